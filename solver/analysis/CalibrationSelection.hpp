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
  double instantaneousRms = 0.0;   ///< RMS of alpha_P - alpha_P^rec over open cells and steps [-]
  double countingFloorRms = 0.0;   ///< its floor for independently placed tracers (Poisson) [-]
  std::optional<double> ksDistance;           ///< RTD against the reference on the tracers' lattice
  std::optional<double> holdupRelativeError;  ///< (holdup - reference) / reference
  std::optional<double> rtdMeanRelativeError;      ///< mean stay against the reference's on the lattice
  std::optional<double> crossingRateRelativeError; ///< stays per member per second against the reference's
  nlohmann::json staysJson;        ///< the StayComparison (null without a reference)
  nlohmann::json sampledPeriodJson;  ///< against the full simulation's sampled period (null without it)
  double rmsOverFloor() const { return countingFloorRms > 0.0 ? instantaneousRms / countingFloorRms : 0.0; }
};

/// Thresholds of the paper's rule; scene-independent job options ("calibration" in the job file).
struct SelectionOptions {
  /// Bed shape agrees when the instantaneous RMS difference is at most (1 + fieldRmsTolerance) x its
  /// counting floor: the over-packing the motion adds is small against the noise of the tracer count.
  double fieldRmsTolerance = 0.25;
  /// Residence times agree when the KS distance to the reference RTD is at most this...
  double ksThreshold = 0.10;
  /// ...and the mean stay and the crossing rate are within this relative tolerance of the reference's
  /// (without a reference: the mean within it of the best-shaped run's).
  double rtdRelativeTolerance = 0.10;
  /// When the selection or the penalty minimum is the largest D0 of the sweep, extend the sweep by
  /// factors of sweepFactor up to the D0 at which u_fluc_max binds (calibration job).
  bool extendSweep = true;
  double sweepFactor = 3.0;
};

/// Reads the optional "calibration" object of a job document (missing keys keep the defaults);
/// rcfd::InputError naming /calibration/<key> and the allowed range for a bad value.
SelectionOptions selectionOptionsFrom(const nlohmann::json& jobDocument);

struct Selection {
  std::size_t penaltyMinimum = 0;  ///< index into the scores
  std::size_t selected = 0;        ///< index into the scores
  bool ruleSatisfied = false;      ///< false: no D0 met both criteria (docs/calibration.md, "Selection")
  std::vector<bool> bedShapeAgrees, residenceTimesAgree;
  std::string reason;              ///< one line: why `selected`
  /// The selection or the penalty minimum is the largest D0 of the list: the optimum may lie beyond.
  bool atUpperEnd = false;
};

/// Applies both selections. `useReference`: judge residence times by the KS distance (every score
/// must then carry one); otherwise by the relative tolerance on the mean. Throws std::invalid_argument
/// for an empty list.
Selection selectD0(const std::vector<D0Scores>& scores, const SelectionOptions& options, bool useReference);

}  // namespace rcfd::analysis
