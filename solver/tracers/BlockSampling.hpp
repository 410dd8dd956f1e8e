#pragma once
/// \file BlockSampling.hpp
/// Trilinear sampling of a step field at the points of a block of tracers, in loops the compiler
/// vectorises (`#pragma omp simd`, AVX-512 gathers): locate every point, gather its 8 corners into a
/// lane-major table, interpolate. A second point of a lane in the same stencil (a midpoint, mostly)
/// reuses the table; only lanes whose stencil changed are gathered again. Internal to the motion kernel.

#include <cstdint>

#include "tracers/Trilinear.hpp"

namespace rcfd::block {

/// Tracers processed together; blocks start at multiples of kBlock whatever the thread count, so each
/// tracer takes the same path in the same vector lane and results are bit-identical for any thread count.
constexpr int kBlock = 64;

/// The trilinear stencils of a block's points: base index, fractions and the 8 corners x 3 components
/// lane-major, so the interpolation reads corners with plain vector loads and a second point in the
/// same stencil (a midpoint, mostly) reuses them without another gather.
struct BlockStencils {
  /// [3 c + d][k]: component d of corner c of lane k, converted to double once when gathered (a
  /// midpoint in the same stencil interpolates without converting again)
  alignas(64) double corner[24][kBlock];
  alignas(64) double fx[kBlock], fy[kBlock], fz[kBlock];
  alignas(64) std::int32_t base[kBlock];
};

/// Base indices and fractions of the points (x, y, z) of a block, into `s`, or the base indices into
/// `newBase` (for regatherChanged) when it is given.
inline void locateBlock(const TrilinearLocator::Constants& q, int count, const double* x, const double* y,
                 const double* z, BlockStencils& s, std::int32_t* newBase) {
  // Plain locals only: the vectoriser gives up on loads through `this` and on per-lane arrays.
  const double ox = q.ox, oy = q.oy, oz = q.oz, ix = q.ix, iy = q.iy, iz = q.iz;
  const double lastX = q.lastX, lastY = q.lastY, lastZ = q.lastZ;
  const int maxX = q.maxX, maxY = q.maxY, maxZ = q.maxZ;
  const std::int32_t sy = q.sy, sz = q.sz;
  std::int32_t* const base = newBase ? newBase : s.base;
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    int lx, ly, lz;
    s.fx[k] = TrilinearLocator::Constants::axis(x[k], ox, ix, lastX, maxX, lx);
    s.fy[k] = TrilinearLocator::Constants::axis(y[k], oy, iy, lastY, maxY, ly);
    s.fz[k] = TrilinearLocator::Constants::axis(z[k], oz, iz, lastZ, maxZ, lz);
    base[k] = lx + ly * sy + lz * sz;
  }
}

/// The corners of every lane's stencil from a step field of 4 floats per cell (vector gathers).
inline void gatherBlock(const float* field, const std::int32_t* off, int count, BlockStencils& s) {
  const std::int32_t o0 = off[0], o1 = off[1], o2 = off[2], o3 = off[3];
  const std::int32_t o4 = off[4], o5 = off[5], o6 = off[6], o7 = off[7];
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    const float* c = field + 4 * s.base[k];
    for (int d = 0; d < 3; ++d) {
      s.corner[0 + d][k] = c[o0 + d], s.corner[3 + d][k] = c[o1 + d];
      s.corner[6 + d][k] = c[o2 + d], s.corner[9 + d][k] = c[o3 + d];
      s.corner[12 + d][k] = c[o4 + d], s.corner[15 + d][k] = c[o5 + d];
      s.corner[18 + d][k] = c[o6 + d], s.corner[21 + d][k] = c[o7 + d];
    }
  }
}

/// Re-gathers, one lane at a time, only the lanes whose stencil base changed to `newBase`.
inline void regatherChanged(const float* field, const std::int32_t* off, int count, const std::int32_t* newBase,
                     BlockStencils& s) {
  for (int k = 0; k < count; ++k) {
    if (newBase[k] == s.base[k]) continue;
    s.base[k] = newBase[k];
    const float* c = field + 4 * newBase[k];
    for (int j = 0; j < 8; ++j) {
      for (int d = 0; d < 3; ++d) s.corner[3 * j + d][k] = c[off[j] + d];
    }
  }
}

/// u = trilinear(corners; fractions) + (ax, ay, az) for the lanes of a block. The arithmetic of
/// trilinear() in Trilinear.hpp (x, then y, then z, in double), so the block path and the scalar path
/// give the same velocities.
inline void interpolateBlock(const BlockStencils& s, int count, const double* ax, const double* ay, const double* az,
                      double* ux, double* uy, double* uz) {
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    const double fx = s.fx[k], fy = s.fy[k], fz = s.fz[k];
    auto lerp = [&](int d) {
      auto at = [&](int c) { return s.corner[3 * c + d][k]; };
      const double x00 = at(0) + fx * (at(1) - at(0));
      const double x10 = at(2) + fx * (at(3) - at(2));
      const double x01 = at(4) + fx * (at(5) - at(4));
      const double x11 = at(6) + fx * (at(7) - at(6));
      const double y0 = x00 + fy * (x10 - x00);
      const double y1 = x01 + fy * (x11 - x01);
      return y0 + fz * (y1 - y0);
    };
    ux[k] = lerp(0) + ax[k];
    uy[k] = lerp(1) + ay[k];
    uz[k] = lerp(2) + az[k];
  }
}

}  // namespace rcfd::block
