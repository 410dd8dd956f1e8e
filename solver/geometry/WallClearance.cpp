#include "geometry/WallClearance.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>

namespace rcfd {
namespace {
constexpr std::int64_t kParallelCells = 4096;  // below this a team costs more than it saves
}  // namespace

std::vector<float> cellWallClearance(const Apparatus& apparatus, const CartesianGrid& grid, double margin) {
  std::vector<float> clearance(std::size_t(grid.cellCount()));
#pragma omp parallel for schedule(static) if (grid.cellCount() > kParallelCells)
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    const double sd = apparatus.signedDistance(grid.cellCenter(ijk[0], ijk[1], ijk[2]));
    clearance[std::size_t(c)] = float(std::max(0.0, sd - margin) * (1.0 - 1e-6));
  }
  return clearance;
}

std::vector<std::uint32_t> nearHalfSpaceMasks(const std::vector<Apparatus::HalfSpace>& halfSpaces,
                                              const CartesianGrid& grid, double margin, double reach) {
  if (halfSpaces.size() > 32) throw std::invalid_argument("nearHalfSpaceMasks: more than 32 half-spaces");
  const double halfDiagonal = 0.5 * grid.spacing.norm();
  const double slack = 1e-6 * grid.spacing.minCoeff();
  const double within = margin + halfDiagonal + reach + slack;
  std::vector<std::uint32_t> masks(std::size_t(grid.cellCount()));
#pragma omp parallel for schedule(static) if (grid.cellCount() > kParallelCells)
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    const Eigen::Vector3d centre = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
    unsigned mask = 0;
    for (std::size_t j = 0; j < halfSpaces.size(); ++j) {
      if (!(halfSpaces[j].n.dot(centre) - halfSpaces[j].c >= within)) mask |= 1u << j;
    }
    masks[std::size_t(c)] = mask;
  }
  return masks;
}

}  // namespace rcfd
