#pragma once
/// \file CellIndex.hpp
/// The grid cell of each of many points, in a loop the compiler vectorises: what
/// `tracer_volume_fraction` maps the tracers with, and what the motion kernel computes for the moved
/// tracers while their positions are still in cache. Both use this one function, so a cell is the same
/// whichever of them found it (runs resumed from a checkpoint stay bit-identical).

#include <cstdint>

#include "geometry/CartesianGrid.hpp"

namespace rcfd {

class CellIndexer {
 public:
  explicit CellIndexer(const CartesianGrid& grid)
      : ox_(grid.origin.x()), oy_(grid.origin.y()), oz_(grid.origin.z()),
        ihx_(1.0 / grid.spacing.x()), ihy_(1.0 / grid.spacing.y()), ihz_(1.0 / grid.spacing.z()),
        nx_(grid.shape[0]), ny_(grid.shape[1]), nz_(grid.shape[2]) {}

  /// out[k] = flat index of the cell holding (x[k], y[k], z[k]); points outside go to the nearest cell.
  /// Multiplications by the inverse spacing, not CartesianGrid's divisions (a vector division costs as
  /// much as the rest of the loop): a point within an ulp of a cell face may land in the neighbour,
  /// which no user of the cells can tell (the motion kernel's wall bound allows for it).
  void cellsOf(int count, const double* x, const double* y, const double* z, std::int32_t* out) const {
    // Plain locals: the vectoriser does not look through members.
    const double ox = ox_, oy = oy_, oz = oz_, ihx = ihx_, ihy = ihy_, ihz = ihz_;
    const int nx = nx_, ny = ny_;
    const double lastX = nx_ - 1, lastY = ny_ - 1, lastZ = nz_ - 1;
#pragma omp simd
    for (int k = 0; k < count; ++k) {
      // Clamped into [0, n - 1] in double, so the truncation is floor (floor itself does not vectorise
      // under GCC's default trapping-math) and no int conversion overflows; NaN gives cell 0.
      double tx = (x[k] - ox) * ihx, ty = (y[k] - oy) * ihy, tz = (z[k] - oz) * ihz;
      tx = tx > 0.0 ? tx : 0.0, ty = ty > 0.0 ? ty : 0.0, tz = tz > 0.0 ? tz : 0.0;
      tx = tx < lastX ? tx : lastX, ty = ty < lastY ? ty : lastY, tz = tz < lastZ ? tz : lastZ;
      const int ci = int(tx), cj = int(ty), ck = int(tz);
      out[k] = (ck * ny + cj) * nx + ci;
    }
  }

 private:
  double ox_, oy_, oz_, ihx_, ihy_, ihz_;
  int nx_, ny_, nz_;
};

}  // namespace rcfd
