#pragma once
/// \file ReferenceCoverage.hpp
/// The full simulation's own coverage distribution: the scene's spray model (the effects `spray` and
/// `deposition` with `tracer_volume_fraction`, Eq. (11)-(15)) run during the database job's reference
/// period on the CFD-DEM's parcels instead of rCFD tracers. Each parcel is a tracer that stands for its
/// cg^3 real particles; per step (the reference samples, 1 / probe_rate apart) the parcels are counted
/// into the grid as tracers are, droplet parcels move with the instant's u_G and deposit on the parcels
/// of their cell with the instant's |u_G - u_P|. Only the particle motion differs from an rCFD spray run
/// over the same duration with one tracer per parcel, so the two coverage distributions compare the
/// motion, which is what rCFD replaces.
///
/// Stored under /reference/coverage/ of the database file (docs/formats.md); compared by spray jobs
/// (analysis/CoverageComparison.hpp).

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fields/FieldDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

namespace h5 {
class File;
}
class TracerEffect;
class TracerCloud;
struct TracerContext;

class ReferenceCoverage {
 public:
  /// Whether the scene's effects ask for a coverage distribution (`coverage` listed): only then does
  /// the database job record the reference one.
  static bool wanted(const Scene& scene);

  /// parcels: DEM parcels (ids 0 .. parcels - 1); openFraction: per cell; dt: the step [s].
  ReferenceCoverage(const Scene& scene, const Apparatus& apparatus, const CartesianGrid& grid,
                    const std::vector<double>& openFraction, std::size_t parcels, double dt, std::uint64_t seed);
  ~ReferenceCoverage();

  /// One step of dt from the present instant: the parcels where they are now (`positions[i]` of the
  /// parcel with permanent id `ids[i]`) and the fields of the instant (alpha_P, u_P, u_G).
  void step(const std::vector<Eigen::Vector3d>& positions, const std::vector<std::uint64_t>& ids,
            std::shared_ptr<const FieldFrame> fields);

  std::int64_t steps() const;
  double duration() const;  ///< steps x dt [s]
  /// Droplets collected per real particle, per parcel id (N_coll of Eq. (15)).
  std::vector<double> dropletsPerParticle() const;

  void save(h5::File& file, const std::string& group) const;
  void load(const h5::File& file, const std::string& group);
  /// Writes /reference/coverage/... into the database file.
  void write(h5::File& database) const;
  /// summary.json's "reference_coverage".
  nlohmann::json summary() const;

 private:
  const Scene& scene_;
  double dt_;
  double singleDropletCoverage_;
  std::unique_ptr<TracerCloud> cloud_;
  std::unique_ptr<TracerContext> context_;
  std::vector<std::unique_ptr<TracerEffect>> effects_;
  std::vector<std::string> effectNames_;
};

}  // namespace rcfd
