#pragma once
/// \file CalibrationSelection.hpp
/// Scores of one calibration run (one D0) and the choice of D0 from them: the penalty minimum (Fig. 8)
/// and the paper's rule, "the lowest viable diffusion coefficient" whose time-averaged bed shape and
/// spray-zone residence times agree (docs/calibration.md).

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace rcfd::analysis {

/// What one tracer run with diffusion coefficient d0 scored.
struct D0Scores {
  double d0 = 0.0;                 ///< [m2/s]
  double penalty = 0.0;            ///< (1/N) ||alpha_P - alpha_P^rec||_2 averaged over the probes [-]
  double rms = 0.0;                ///< RMS of alpha_P - alpha_P^rec averaged over the probes [-]
  double fieldRms = 0.0;           ///< volume-weighted RMS of time-averaged alpha_P differences [-]
  double fieldRmsMidplane = 0.0;   ///< the same over the mid-plane z = depth / 2 [-]
  double holdupMean = 0.0;         ///< spray-zone holdup [particles]
  double rtdMean = 0.0;            ///< mean spray-zone residence time [s]
  double rtdMedian = 0.0;          ///< [s]
  long long stays = 0;             ///< completed spray-zone stays counted
  std::optional<double> ksDistance;           ///< RTD against the reference (when it exists)
  std::optional<double> holdupRelativeError;  ///< (holdup - reference) / reference
};

/// Thresholds of the paper's rule; scene-independent job options ("calibration" in the job file).
struct SelectionOptions {
  /// Bed shape agrees when fieldRms <= (1 + fieldRmsTolerance) x the lowest fieldRms of all D0.
  double fieldRmsTolerance = 0.25;
  /// Residence times agree when the KS distance to the reference RTD is at most this.
  double ksThreshold = 0.15;
  /// Without a reference: mean residence time within this relative tolerance of the mean of the run
  /// with the best bed shape.
  double rtdRelativeTolerance = 0.10;
};

/// Reads the optional "calibration" object of a job document (missing keys keep the defaults);
/// rcfd::InputError naming /calibration/<key> and the allowed range for a bad value.
SelectionOptions selectionOptionsFrom(const nlohmann::json& jobDocument);

struct Selection {
  std::size_t penaltyMinimum = 0;  ///< index into the scores
  std::size_t selected = 0;        ///< index into the scores
  bool ruleSatisfied = false;      ///< false: no D0 met both criteria, fell back to bed shape only
  std::vector<bool> bedShapeAgrees, residenceTimesAgree;
  std::string reason;              ///< one line: why `selected`
};

/// Applies both selections. `useReference`: judge residence times by the KS distance (every score
/// must then carry one); otherwise by the relative tolerance on the mean. Throws std::invalid_argument
/// for an empty list.
Selection selectD0(const std::vector<D0Scores>& scores, const SelectionOptions& options, bool useReference);

}  // namespace rcfd::analysis
