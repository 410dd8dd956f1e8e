#pragma once
/// \file DemFilling.hpp
/// Filling the apparatus: insert the bed mass as parcels at random non-overlapping positions in a
/// region above the bed (batch after batch, each batch falling clear before the next), then let the
/// bed settle under gravity (DEM only) until its kinetic energy is small. A DEM-only database job
/// (the scene's effects without `gas`) runs this and starts the gas run from the settled state.

#include <Eigen/Core>
#include <cstdint>
#include <functional>

#include "cfddem/DemSystem.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

/// Insertion attempts between two polls of FillOptions::stop_requested (a few milliseconds of work).
inline constexpr long kInsertionAttemptsPerPoll = 4096;

/// Inserting parcels batch by batch and letting each batch fall; then settling the whole bed.
enum class FillStage { Inserting, Settling };

struct FillRegion {
  Eigen::Vector3d lower = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d upper = Eigen::Vector3d::Zero();  ///< [m]
};

struct FillOptions {
  std::uint64_t seed = 1;          ///< random positions (deterministic for a seed)
  double max_settle_time = 0.5;    ///< settling stops after this time at the latest [s]
  /// Settled when the kinetic energy per parcel is below this fraction of m g r (mean speed about
  /// sqrt(2 fraction g r)) [-].
  double settled_energy_fraction = 1e-3;
  int max_batches = 200;           ///< refuse to go on when the region never takes all parcels
  /// Polled before every DEM step and every kInsertionAttemptsPerPoll insertion attempts (a step of a
  /// large bed takes a good part of a second, a millisecond of simulated time can take minutes); true
  /// stops the filling with rcfd::Cancelled (a half-filled bed is no state to resume from: the caller
  /// fills again). Empty: never.
  std::function<bool()> stop_requested;
  /// Called as the filling enters each stage (the job's progress names it). Empty: not called.
  std::function<void(FillStage)> stage_started;
  /// Called before every DEM step and with every stop poll of the insertion: the stage and how far it
  /// is, in [0, 1], non-decreasing within a stage and 1 at its end (a large bed fills for hours, and
  /// its job's progress must move meanwhile). Inserting: the parcel DEM steps done against those
  /// expected once the first batch shows how many parcels a batch takes (each later batch as many, the
  /// last one the rest, each falling as long as the first with every parcel inserted so far), held
  /// below 1 until the last batch has fallen. Settling: fillSettleFraction(). Empty: not called.
  std::function<void(FillStage, double)> progress;
  /// A new parcel's centre must also lie inside the open region by this test (the apparatus's signed
  /// distance > 0): the walls' clearance is a distance, the same in front of a wall and behind it, and
  /// a region that reaches behind a steep V-bottom would otherwise take parcels there. Empty: any.
  std::function<bool(const Eigen::Vector3d&)> inside;
};

struct FillResult {
  long inserted = 0;          ///< parcels inserted
  int batches = 0;
  double fill_time = 0.0;     ///< simulated time spent inserting [s]
  double settle_time = 0.0;   ///< simulated time spent settling [s]
  double kinetic_energy = 0.0;  ///< at the end [J]
  bool settled = false;       ///< the energy criterion was met (else max_settle_time ran out)
};

/// How far settling is, in [0, 1], from what decides its end: the larger of the time run against
/// `maxTime` and the kinetic energy's way down to the criterion on a log scale,
/// ln(E0 / E) / ln(E0 / E_settled), E0 the energy at the first check. Settling ends at the first of the
/// two, and the energy falls about exponentially, so each moves about linearly towards its end. Not
/// monotone by itself (the energy of a settling bed rises now and then): callers keep the maximum.
double fillSettleFraction(double time, double maxTime, double energy, double firstEnergy, double settledEnergy);

/// DEM steps a batch is given to fall clear of `region` before the next (sqrt(2 h / g), h the
/// region's height plus a parcel diameter).
long fallStepsPerBatch(const DemSystem& dem, const FillRegion& region);

/// Number of parcels of the scene's bed: M_P / (cg^3 m_P), rounded to the nearest integer.
long parcelsForBedMass(const Scene& scene);

/// The paper's insertion region for the prismatic spouted bed, 0.2 m < y < 0.3 m over the chamber's
/// width and depth (a chamber lower than 0.3 m: its upper third, above the V-bottom's top); for a box,
/// the upper third.
FillRegion defaultFillRegion(const ApparatusSpec& apparatus);

/// Inserts `count` parcels in `region` (clear of walls and of each other), lets them fall and settles.
/// Throws rcfd::RunError when the region cannot take the parcels within max_batches, rcfd::Cancelled
/// when options.stop_requested says so.
FillResult fillAndSettle(DemSystem& dem, const FillRegion& region, long count,
                         const FillOptions& options = {});

/// Runs until the kinetic energy criterion holds (checked every millisecond of simulated time) or
/// max_time passes; returns the time run [s]. `stop_requested` as in FillOptions; `progress`, if
/// given, before every DEM step with the running maximum of fillSettleFraction() and with 1 at the end.
double settle(DemSystem& dem, double max_time, double settled_energy_fraction, bool* settled = nullptr,
              const std::function<bool()>& stop_requested = {},
              const std::function<void(double)>& progress = {});

}  // namespace rcfd
