#pragma once
/// \file DatabaseProgress.hpp
/// The database job's progress (jobs/Progress.hpp): its phases, how far each is, and one fraction of
/// the whole job weighted by each phase's expected cost, so that the fraction grows about linearly in
/// wall time and the rate of one phase predicts the rest (the ETA of the first minute holds).
///
/// Cost model, in units of one parcel's DEM step (the DEM's work is per parcel and step):
///  - fill: each batch falls fallStepsPerBatch() DEM steps with the parcels inserted so far. Beds
///    take two batches (the quick slice and the 3D ProCell bed, docs/performance.md), the first with
///    about half the parcels: 1.5 N S for N parcels and S steps per batch.
///  - settle: N parcels for at most settle_time (settling ends earlier once the bed is still; the
///    fraction then moves on to the coupled run at once, by at most this phase's share).
///  - coupled run (ramp, warm-up, sample, reference): N + 0.6 cells per DEM step with the gas, N
///    without. The gas and the coupling take 36-53 % of a coupled step: the DEM's share is 47 % on
///    the quick slice (1.74 cells per parcel) and 58-64 % on the 3D ProCell (1.26 cells per parcel),
///    0.50-0.65 parcel steps per cell and DEM step (docs/performance.md, "Coupled CFD-DEM").
///    Frames and reference samples cost little beside the steps.

#include <cstdint>

#include "scene/DatabaseSchedule.hpp"

namespace rcfd {

/// Parcel DEM steps a grid cell costs per DEM step of the coupled run (gas and coupling).
inline constexpr double kCoupledCostPerCell = 0.6;

class DatabaseProgress {
 public:
  /// `parcels` of the bed, `fallSteps` per filling batch, `cells` of the grid, `gas`: the scene runs
  /// the gas.
  DatabaseProgress(const DatabaseSchedule& plan, double settleTime, long parcels, long fallSteps,
                   std::int64_t cells, bool gas);

  /// The whole job's fraction while filling, settling, and `offset` DEM steps after settling, from
  /// the stage's own fraction (FillOptions::progress).
  double fill(double stageFraction) const;
  double settle(double stageFraction) const;
  double coupled(std::int64_t offset) const;

  double fillShare() const { return fill_ / total_; }
  double settleShare() const { return settle_ / total_; }

 private:
  double fill_, settle_, perStep_, total_;
  std::int64_t end_;
};

/// The phase of the coupled run `offset` DEM steps after settling ("ramp", "warmup", "sample",
/// "reference"), and how far it is in [0, 1].
const char* coupledPhase(const DatabaseSchedule& plan, std::int64_t offset);
double coupledPhaseFraction(const DatabaseSchedule& plan, std::int64_t offset);

}  // namespace rcfd
