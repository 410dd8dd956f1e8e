#pragma once
/// \file ReferenceStatistics.hpp
/// Spray-zone statistics of the full CFD-DEM simulation, stored by the database job in the field
/// database file (layout in docs/calibration.md). Optional: an imported database has none, and the
/// calibration then reports which scores it could not compute.

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/Scene.hpp"

namespace rcfd::analysis {

namespace reference_layout {
inline constexpr const char* durations = "/reference/residence_time/durations_s";  ///< float64 [M]
inline constexpr const char* holdup = "/reference/holdup/particles";               ///< float64 [T], attr dt
inline constexpr const char* holdupDt = "dt";                                      ///< [s]
/// Optional attributes of `durations`: the members (parcels) whose stays were recorded, and the length
/// of the period they were recorded over [s] (crossing rates).
inline constexpr const char* members = "members";
inline constexpr const char* period = "period_s";
/// Optional: the coverage the scene's spray model gives on the full simulation's own parcels over its
/// reference period (spray/ReferenceCoverage.hpp): droplets per real particle, per parcel id, with the
/// attributes below; and the spray's books [injected, deposited, airborne, overspray at walls, overspray
/// at the outlet, residual] in droplets.
inline constexpr const char* coverageDroplets = "/reference/coverage/droplets_per_particle";  ///< float64 [N]
inline constexpr const char* coverageBalance = "/reference/coverage/balance_droplets";       ///< float64 [6]
inline constexpr const char* coverageDuration = "duration_s";                  ///< length of the spray [s]
inline constexpr const char* coverageDt = "dt";                                ///< its step [s]
inline constexpr const char* coverageParticlesPerParcel = "particles_per_parcel";  ///< cg^3 [-]
inline constexpr const char* coverageSingleDroplet = "f";  ///< Eq. (15)'s f of the scene [-]
/// Optional: the same stays and holdup over the sampled period (the frames'), in the same layout.
inline constexpr const char* sampledDurations = "/reference/sampled_period/residence_time/durations_s";
inline constexpr const char* sampledHoldup = "/reference/sampled_period/holdup/particles";
}  // namespace reference_layout

struct ReferenceStatistics {
  std::vector<double> durations;  ///< completed spray-zone stays [s]; empty if absent
  std::vector<double> holdup;     ///< spray-zone holdup series [particles]; empty if absent
  double holdupDt = 0.0;          ///< [s] between holdup samples
  double durationsDt = 0.0;       ///< [s] sampling interval of the stays (attr dt of durations; 0: unknown)
  double members = 0.0;           ///< members whose stays were recorded (0: unknown)
  double period = 0.0;            ///< [s] over which they were recorded (0: unknown)
  std::vector<std::string> missing;  ///< datasets not found (their names from reference_layout)
  /// Why the stays and the holdup were left out though present: the database's scene counted them in
  /// another spray zone than the job's (empty when they were kept).
  std::string zoneMismatch;
  /// The full simulation's stays and holdup over the sampled period, the one the frames come from (null
  /// when the database has none): the tracers can at best move like the particles of that period, and
  /// the two periods' difference is the full simulation's own.
  std::shared_ptr<const ReferenceStatistics> sampledPeriod;

  bool hasDurations() const { return !durations.empty(); }
  bool hasHoldup() const { return !holdup.empty(); }
  double holdupMean() const;
  /// Length of the recording [s]: the attribute, else the holdup series' length (0: unknown).
  double recordedPeriod() const { return period > 0.0 ? period : double(holdup.size()) * holdupDt; }
};

/// The members whose stays the reference counted: its own attribute, else the real particles of the
/// scene's bed (bed mass over the mass of one particle), as the tracers' holdup is counted.
double referenceMembers(const ReferenceStatistics& reference, double bedMass, double particleDensity,
                        double particleDiameter);

/// A run's stays (counts per whole step of dt, over `tracers` members for `runPeriod` s) and mean holdup
/// [particles] against one period of the full simulation: {"period_s", "holdup_relative_error",
/// "mean_relative_error", "crossing_rate_relative_error"} (null where the period lacks the dataset) and,
/// where it has them, "holdup_mean" and "ks_distance". `fallbackMembers`: the members when the period
/// does not say.
nlohmann::json compareWithPeriod(const ReferenceStatistics& period, const std::vector<std::int64_t>& stepCounts,
                                 double dt, double tracers, double runPeriod, double runHoldupMean,
                                 double fallbackMembers);

/// Reads the reference statistics of a database file. Absent datasets go into `missing`; present but
/// malformed ones (non-finite or negative values, empty, missing or non-positive dt) are an
/// rcfd::InputError naming the file and dataset.
/// With `zone`, stays and holdup counted in another spray zone (the one in the database's `/scene`, which
/// the database job counted them in) are left out and `zoneMismatch` says why: they would be compared
/// with tracers counted elsewhere.
ReferenceStatistics readReferenceStatistics(const std::string& databasePath, const SprayZoneSpec* zone = nullptr);

}  // namespace rcfd::analysis
