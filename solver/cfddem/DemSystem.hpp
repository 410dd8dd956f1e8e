#pragma once
/// \file DemSystem.hpp
/// The DEM: particles, walls, a contact model (and optionally a rolling model), the neighbour list and
/// the velocity-Verlet integrator with gravity. One step:
///   v += dt/2 F/m, omega += dt/2 T/I;  x += dt v;  (rebuild the list if needed);  forces;
///   v += dt/2 F/m, omega += dt/2 T/I.
/// Forces are computed per pair and gathered per particle in a fixed order: bit-identical results
/// for any number of OpenMP threads (docs/dem.md, "Determinism").

#include <memory>
#include <string>

#include "cfddem/ContactModel.hpp"
#include "cfddem/DemMaterial.hpp"
#include "cfddem/DemParticles.hpp"
#include "cfddem/DemWalls.hpp"
#include "cfddem/NeighbourList.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

namespace h5 {
class File;
}

/// Smaller systems are never sorted: they fit in cache, and tests address particles by index.
inline constexpr long kDemSortMinParticles = 1024;

struct DemSettings {
  double time_step = 1e-6;                 ///< dt_DEM [s]
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, -9.81, 0.0);  ///< [m/s2]
  double skin_fraction = 0.4;              ///< neighbour-list skin as a fraction of the parcel radius
  double max_rayleigh_fraction = 0.3;      ///< dt above this fraction of the Rayleigh time: refused
  double max_overlap_fraction = 0.003;     ///< warn when an overlap exceeds this fraction of r
  /// Sort the particles spatially (cell order) every this many list builds, for cache locality
  /// (a random order costs a factor of about 1.8); 0: never. Only systems of at least
  /// kDemSortMinParticles particles are sorted. Indices change; DemParticles::id does not.
  int sort_interval = 10;
  /// Benchmarks only: the serial reference scheme (pair forces added straight into the particles,
  /// one thread) to measure what the deterministic per-pair gather costs. Ignored (with the
  /// deterministic scheme used) when more than one OpenMP thread is available.
  bool serial_direct_accumulation = false;
  std::string contact_model = "hertz_mindlin";
  std::string rolling_model;               ///< empty: no rolling friction; else e.g. "cdt"
};

/// Wall-clock seconds spent in each phase since construction (for benchmarks).
struct DemTimings {
  double drift = 0.0;   ///< first half kick and drift (with the displacement test)
  double build = 0.0;   ///< neighbour-list rebuilds
  double pairs = 0.0;   ///< particle-particle forces into per-pair slots
  double gather = 0.0;  ///< per-particle gather, wall contacts and the second half kick
};

/// Figures of the last step.
struct DemStepStats {
  double max_overlap_fraction = 0.0;  ///< largest delta / r [-]
  long contacts = 0;                  ///< touching particle pairs
  long wall_contacts = 0;
};

class DemSystem {
 public:
  /// Checks the time step against the Rayleigh time (rcfd::InputError naming /dem/time_step).
  DemSystem(const DemMaterial& material, DemWalls walls, const DemSettings& settings);

  /// The DEM of a scene: material with coarse graining, dem settings, rolling friction when the
  /// effect `rolling_friction` is listed.
  static DemSettings settingsFromScene(const Scene& scene);

  DemParticles& particles() { return particles_; }
  const DemParticles& particles() const { return particles_; }
  const DemWalls& walls() const { return walls_; }
  const DemMaterial& material() const { return material_; }
  const DemSettings& settings() const { return settings_; }
  const NeighbourList& neighbourList() const { return list_; }
  const ContactModel& contactModel() const { return *model_; }
  bool hasRollingModel() const { return rolling_ != nullptr; }

  /// Adds a parcel of the material's radius and density; returns its index.
  std::size_t addParticle(const Eigen::Vector3d& x, const Eigen::Vector3d& v = Eigen::Vector3d::Zero());

  /// Changes gravity [m/s2] (e.g. to tilt a test set-up); takes effect at the next force evaluation.
  void setGravity(const Eigen::Vector3d& g) { settings_.gravity = g; }

  void step();
  void run(long steps);

  /// Whole state (particles with ids, fluid forces, neighbour list with the tangential contact
  /// history of pairs and walls, clock) into / from group of a checkpoint file (DemState.cpp): a
  /// loaded system continues bit-identically to the saved one. The system loaded into must have been
  /// built with the same material, walls and settings.
  void saveState(h5::File& file, const std::string& group) const;
  void loadState(const h5::File& file, const std::string& group);

  double time() const { return time_; }
  long steps() const { return steps_; }
  double timeStep() const { return settings_.time_step; }
  /// dt / t_Rayleigh, reported when the system is built [-].
  double rayleighFraction() const { return rayleigh_fraction_; }
  const DemStepStats& lastStats() const { return stats_; }
  const DemTimings& timings() const { return timings_; }
  /// Largest overlap fraction seen since construction [-].
  double maxOverlapFractionSeen() const { return max_overlap_seen_; }

  /// Elastic energy stored in the Hertz contacts, sum of 8/15 Y* sqrt(R*) delta^(5/2) [J].
  double elasticEnergy() const;
  /// Kinetic + gravitational (relative to the origin) + elastic energy [J].
  double totalEnergy() const;

 private:
  /// Forces and torques of the current positions; with final_kick also the second half kick.
  /// moved: 1/0 whether the caller found a displacement above half the skin, -1 to test here.
  void computeForces(bool final_kick, int moved);
  void resizeState();
  void sortParticles();

  DemMaterial material_;
  DemWalls walls_;
  DemSettings settings_;
  std::unique_ptr<ContactModel> model_;
  std::unique_ptr<RollingModel> rolling_;
  DemParticles particles_;
  NeighbourList list_;
  WallHistory wall_history_;
  PairForces pair_forces_;
  DemStepStats stats_;
  DemTimings timings_;
  double time_ = 0.0;
  long steps_ = 0;
  long builds_since_sort_ = 0;
  double rayleigh_fraction_ = 0.0;
  double max_overlap_seen_ = 0.0;
  bool forces_valid_ = false;
  bool overlap_warned_ = false;
};

}  // namespace rcfd
