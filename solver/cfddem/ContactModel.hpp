#pragma once
/// \file ContactModel.hpp
/// Contact models of the DEM, selected by name through rcfd::Registry (LAMMPS pair styles): a contact
/// model computes all particle-particle contacts of the neighbour list and all particle-wall contacts
/// in one call each, so the per-contact work is inlined, not a virtual call. Rolling friction is a
/// separate model (scene effect `rolling_friction`) that a contact model applies when given one.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cfddem/DemMaterial.hpp"
#include "cfddem/DemParticles.hpp"
#include "cfddem/DemWalls.hpp"
#include "cfddem/NeighbourList.hpp"
#include "core/Registry.hpp"

namespace rcfd {

/// Tangential history of particle-wall contacts: up to `slots` per particle, keyed by wall primitive.
struct WallHistory {
  static constexpr int slots = 8;
  std::vector<int> wall;                 ///< primitive index, -1 for a free slot (size N * slots)
  std::vector<Eigen::Vector3d> shear;    ///< tangential displacement [m] (size N * slots)
  void resize(std::size_t n) {
    wall.resize(n * slots, -1);
    shear.resize(n * slots, Eigen::Vector3d::Zero());
  }
};

/// Per-pair results of the particle-particle pass for the pair's second member j (indexed like
/// the neighbour list's pairs). The first member's share is summed in the pair loop itself.
struct PairForces {
  std::vector<std::uint8_t> active;       ///< 1 if the pair touches (only then are the rest set)
  std::vector<Eigen::Vector3d> force;     ///< force on i (on j: the opposite) [N]
  std::vector<Eigen::Vector3d> torque_j;  ///< torque on j [N m]
  void resize(std::size_t n) {
    active.resize(n);
    force.resize(n);
    torque_j.resize(n);
  }
};

/// Everything a contact model reads and writes in one force evaluation.
struct ContactContext {
  DemParticles& particles;
  NeighbourList& list;
  const DemWalls& walls;
  WallHistory& wall_history;
  PairForces& pair_forces;
  double dt;                        ///< DEM time step [s] (tangential history increments)
  /// Serial reference mode (benchmarks only): the pair loop adds straight into the particles'
  /// accumulators (pre-set with gravity) instead of per-pair slots; one thread, no gather.
  bool direct = false;
  double max_overlap_fraction = 0;  ///< out: largest delta / r of any contact this evaluation
  long contacts = 0;                ///< out: number of touching particle-particle pairs
  long wall_contacts = 0;           ///< out: number of particle-wall contacts
};

/// A rolling-resistance model (the effect `rolling_friction`). Its torque law is applied inside the
/// contact model's loop; the object names the law and carries nothing else.
class RollingModel {
 public:
  virtual ~RollingModel() = default;
  virtual std::string name() const = 0;
};

class ContactModel {
 public:
  virtual ~ContactModel() = default;
  virtual std::string name() const = 0;
  /// Uses `rolling` (may be null: no rolling resistance). Refuses a law it does not implement.
  virtual void setRollingModel(const RollingModel* rolling) = 0;
  /// Particle-particle contacts: sets particle i's accumulators to the sum over its own row (pairs
  /// (i, j), in row order), writes the second members' shares into ctx.pair_forces (active = 0
  /// when apart) and updates the tangential history. Gravity and the second members' shares are
  /// added afterwards in a fixed order (DemSystem), so the result does not depend on threads.
  virtual void computePairs(ContactContext& ctx) const = 0;
  /// Particle-wall contacts of particle i: adds to `force` and `torque`, updates i's wall history;
  /// raises `max_overlap` (delta / r) and counts contacts. Called concurrently for different i.
  virtual void computeWalls(ContactContext& ctx, long i, Eigen::Vector3d& force,
                            Eigen::Vector3d& torque, double& max_overlap, long& contacts) const = 0;
};

using ContactModelRegistry = Registry<ContactModel, const DemMaterial&>;
using RollingModelRegistry = Registry<RollingModel, const DemMaterial&>;

}  // namespace rcfd
