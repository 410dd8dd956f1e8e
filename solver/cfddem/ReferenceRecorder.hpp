#pragma once
/// \file ReferenceRecorder.hpp
/// The database job's reference series, recorded from the actual parcel motion at one fixed interval
/// (scene dem.probe_rate), counted in samples from the first frame (sample 0 = frame 0):
///  - during the sampled and the reference periods: u_P,y at each probe (the cell holding it, for the
///    Eq. (8) criterion from a signal sampled faster than dt_rec) and the bed pressure drop;
///  - from sample `referenceStart` on: the spray-zone holdup (parcels inside, reported in real
///    particles, cg^3 per parcel, as the calibration compares them) and every completed stay of a
///    parcel (by its permanent id) in the spray zone;
///  - before it, the same holdup and stays over the sampled period, the one the frames come from: the
///    full simulation against itself (one period against the next) says how far two of its periods
///    differ, the least any comparison of tracers with one of them can be trusted to.
/// Stored under /reference/ in the database file (docs/formats.md, docs/calibration.md).

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/ZoneStays.hpp"
#include "cfddem/DemParticles.hpp"
#include "geometry/CartesianGrid.hpp"
#include "geometry/SprayZone.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

namespace h5 {
class File;
}

namespace reference_series {
inline constexpr const char* probeVelocity = "/reference/probes/u_p_y";  ///< float64 [S][P] [m/s]
inline constexpr const char* probeNames = "/reference/probes/names";     ///< string: JSON array
inline constexpr const char* probePositions = "/reference/probes/positions";  ///< float64 [P][3] [m]
inline constexpr const char* pressureDrop = "/reference/pressure_drop/pa";    ///< float64 [S] [Pa]
inline constexpr const char* holdupParcels = "/reference/holdup/parcels";     ///< float64 [R]
}  // namespace reference_series

/// summary.json's "pressure_drop" of a series sampled every `dt` [s] (stored at
/// reference_series::pressureDrop): samples, mean and standard deviation [Pa], the dominant frequency
/// and its resolution [Hz]; the statistics null below 4 samples.
nlohmann::json pressureDropSummary(const std::vector<double>& pa, double dt);

class ReferenceRecorder {
 public:
  /// parcels: number of DEM parcels (ids 0 .. parcels-1); dt: sampling interval [s]; referenceStart:
  /// the first sample of the reference period.
  ReferenceRecorder(const Scene& scene, const CartesianGrid& grid, std::size_t parcels, double dt,
                    std::int64_t referenceStart);

  /// Records sample `samples()`: the probes from the per-cell particle velocity, the pressure drop and,
  /// in the reference period, holdup and stays of `parcels`.
  void record(const std::vector<Eigen::Vector3d>& particleVelocity, double pressureDrop,
              const DemParticles& parcels);

  std::int64_t samples() const { return std::int64_t(pressureDrop_.size()); }
  double dt() const { return dt_; }
  std::int64_t referenceStart() const { return referenceStart_; }
  const std::vector<double>& pressureDrop() const { return pressureDrop_; }
  /// u_P,y of probe p over samples [first, last) [m/s].
  std::vector<double> probeSeries(std::size_t p, std::int64_t first, std::int64_t last) const;
  const ZoneStays& stays() const { return stays_; }
  /// Holdup series of the reference period [parcels].
  const std::vector<std::int64_t>& holdupParcels() const { return holdup_; }
  /// The same over the sampled period, and its stays; complete only when `sampledPeriodRecorded()`
  /// (a job resumed from a checkpoint that did not keep them has none).
  const std::vector<std::int64_t>& sampledHoldupParcels() const { return sampledHoldup_; }
  const ZoneStays& sampledStays() const { return sampledStays_; }
  bool sampledPeriodRecorded() const {
    return sampledRecorded_ && referenceStart_ > 0 && sampledHoldup_.size() == std::size_t(referenceStart_);
  }
  double particlesPerParcel() const { return particlesPerParcel_; }

  /// Checkpoint state.
  void save(h5::File& file, const std::string& group) const;
  void load(const h5::File& file, const std::string& group);

  /// Writes /reference/... into the (closed-for-appending) database file: durations_s and the holdup
  /// in particles in the layout of analysis/ReferenceStatistics.hpp, plus probes and pressure drop.
  void write(h5::File& database) const;

  /// summary.json parts: "residence_time", "holdup", "pressure_drop", "sampling_criterion" (Eq. (8)
  /// of each probe's u_P,y over the sampled period, against dtRec) and "periods" (the sampled period's
  /// holdup and stays against the reference period's, null when not recorded).
  nlohmann::json summary(double dtRec, int residenceTimeBins) const;

 private:
  const Scene& scene_;
  SprayZone zone_;
  double dt_;
  std::int64_t referenceStart_;
  double particlesPerParcel_;
  std::vector<std::int64_t> probeCells_;
  std::vector<double> probeVelocity_;  ///< [S][P]
  std::vector<double> pressureDrop_;   ///< [S]
  std::vector<std::int64_t> holdup_;   ///< [R] parcels in the zone
  ZoneStays stays_;                    ///< by parcel id, in samples
  std::vector<std::int64_t> sampledHoldup_;  ///< the sampled period's, [referenceStart]
  ZoneStays sampledStays_;
  bool sampledRecorded_ = true;
  nlohmann::json periodsSummary() const;
  /// Counts the parcels in the zone at sample s into `holdup` and `stays` (stays from `countFrom`).
  void observeZone(const DemParticles& parcels, std::int64_t s, std::int64_t countFrom, ZoneStays& stays,
                   std::vector<std::int64_t>& holdup);
};

}  // namespace rcfd
