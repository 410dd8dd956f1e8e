#include "geometry/WallClearance.hpp"

#include <algorithm>
#include <cstdint>

namespace rcfd {

std::vector<float> cellWallClearance(const Apparatus& apparatus, const CartesianGrid& grid, double margin) {
  constexpr std::int64_t kParallelCells = 4096;  // below this a team costs more than it saves
  std::vector<float> clearance(std::size_t(grid.cellCount()));
#pragma omp parallel for schedule(static) if (grid.cellCount() > kParallelCells)
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    const double sd = apparatus.signedDistance(grid.cellCenter(ijk[0], ijk[1], ijk[2]));
    clearance[std::size_t(c)] = float(std::max(0.0, sd - margin) * (1.0 - 1e-6));
  }
  return clearance;
}

}  // namespace rcfd
