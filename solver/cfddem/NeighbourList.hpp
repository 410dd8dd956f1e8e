#pragma once
/// \file NeighbourList.hpp
/// Verlet neighbour list built with linked cells: a half list (each pair once, j > i) in compressed
/// rows, with a skin so that it stays valid until some particle has moved more than half the skin.
/// Each pair carries its tangential contact history, which a rebuild carries over by pair (i, j).
/// The transpose (for every j the pairs it is the second member of, in pair order) lets forces be
/// gathered per particle in a fixed order, so results do not depend on the thread count.
/// The list also keeps, per particle, the wall primitives within reach (DemWalls).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "cfddem/DemParticles.hpp"
#include "cfddem/DemWalls.hpp"

namespace rcfd {

class NeighbourList {
 public:
  using Index = std::uint32_t;
  /// Linked cells allowed per particle before the cells grow beyond the interaction distance (4 bytes
  /// of offsets each: a sparse bed in a tall chamber needs tens of cells per particle).
  static constexpr long kMaxCellsPerParticle = 64;

  /// skin: extra distance beyond contact [m] within which pairs are listed.
  explicit NeighbourList(double skin = 0.0) : skin_(skin) {}

  double skin() const { return skin_; }
  void setSkin(double skin) { skin_ = skin; }

  /// True when a particle moved more than half the skin since the last build (or none was made).
  bool needsRebuild(const DemParticles& p) const;

  /// Positions at the last build and the squared displacement (skin/2)^2 that triggers a rebuild,
  /// for integrators that test the displacement while they move the particles.
  const std::vector<Eigen::Vector3d>& positionsAtBuild() const { return x_at_build_; }
  double rebuildDistance2() const { return 0.25 * skin_ * skin_; }

  /// Rebuilds pairs and wall candidates; keeps the tangential history of pairs listed before.
  void build(const DemParticles& p, const DemWalls& walls);

  /// Re-expresses the list (and its tangential history) after the particles were reordered: new
  /// index k is old index perm[k]. Pairs whose order flips get the opposite history. The next
  /// build() must follow (the list is no longer sorted for the new positions).
  void permute(const std::vector<std::size_t>& perm);

  std::size_t pairs() const { return j.size(); }
  long builds() const { return builds_; }

  /// Checkpoints: the list's public arrays are saved as they are; this restores the rest (positions at
  /// the last build and the build count), so a restored list rebuilds exactly when the original would.
  void restore(std::vector<Eigen::Vector3d> x_at_build, long builds) {
    x_at_build_ = std::move(x_at_build);
    builds_ = builds;
  }

  std::vector<Index> row_start;  ///< pairs of particle i are [row_start[i], row_start[i+1])
  std::vector<Index> j;          ///< second member of each pair (j > i)
  std::vector<Eigen::Vector3d> shear;  ///< tangential history per pair [m]
  std::vector<Index> col_start;  ///< pairs where particle k is second: col_pair[col_start[k]...]
  std::vector<Index> col_pair;   ///< pair indices, increasing within a column

  std::vector<Index> wall_start;  ///< wall candidates of particle i: wall_id[wall_start[i]...]
  std::vector<Index> wall_id;

 private:
  double skin_;
  long builds_ = 0;
  std::vector<Eigen::Vector3d> x_at_build_;
  // cells
  std::vector<Index> cell_start_, cell_particles_;
};

}  // namespace rcfd
