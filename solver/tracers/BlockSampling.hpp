#pragma once
/// \file BlockSampling.hpp
/// Trilinear sampling of a step field (4 floats per cell, or a frame's own 3) at the points of a block
/// of tracers: locate every point in a loop the compiler vectorises, then combine each lane's 8 corners.
/// With AVX2 and FMA and 4 floats per cell, a lane's corners come in as 4 contiguous 32-byte loads (the
/// x-neighbours of a corner are adjacent in memory) and are combined two corners and 3 components at a
/// time: 4 loads and 7 vector operations in place of 24 element gathers (AVX-512 gathers cost about one
/// load per element). (3 floats per cell, the frames' layout, would save the step field's copy, but its
/// pair loads split cache lines more often and need a shuffle; docs/performance.md.) Both the block path
/// and ReferenceMotion combine corners with interpolateCorners() (float, fused multiply-adds, z then y
/// then x), so they give bit-identical velocities. Internal to the motion kernel.

#include <bit>
#include <cmath>
#include <cstdint>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#define RCFD_BLOCK_SAMPLING_AVX2 1
#endif

#include "core/IsaNamespace.hpp"
#include "tracers/Trilinear.hpp"

namespace rcfd::block {

/// Tracers processed together; blocks start at multiples of kBlock whatever the thread count, so each
/// tracer takes the same path in the same vector lane and results are bit-identical for any thread count.
constexpr int kBlock = 64;

/// The trilinear stencils of a block's points: base index and fractions (in float, the precision of
/// the step field and of the combination).
struct BlockStencils {
  alignas(64) float fx[kBlock], fy[kBlock], fz[kBlock];
  alignas(64) std::int32_t base[kBlock];
  /// The grid coordinates of the points last located and u sampled there, in float (the midpoint rule
  /// steps from them)
  alignas(64) float gx[kBlock], gy[kBlock], gz[kBlock];
  alignas(64) float ux[kBlock], uy[kBlock], uz[kBlock];
};

/// The combination of the 8 corners (corner c at field + off[c]; bit 0 of c is x, bit 1 y, bit 2 z)
/// with fractions (fx, fy, fz) for the first `Components` floats of a cell: linear interpolation along
/// z, then y, then x, each a + f (b - a) as one fused multiply-add in float. Exact for a uniform field.
template <int Components>
inline void combineCorners(const float* field, const std::int32_t* off, float fx, float fy, float fz,
                           float out[Components]) {
  for (int d = 0; d < Components; ++d) {
    float t[4];
    for (int j = 0; j < 4; ++j) {
      const float a = field[off[j] + d], b = field[off[j + 4] + d];
      t[j] = std::fma(fz, b - a, a);
    }
    const float s0 = std::fma(fy, t[2] - t[0], t[0]);
    const float s1 = std::fma(fy, t[3] - t[1], t[1]);
    out[d] = std::fma(fx, s1 - s0, s0);
  }
}

/// u at the point: the scalar reference of sampleBlock().
inline void interpolateCorners(const float* field, const std::int32_t* off, float fx, float fy, float fz,
                               float out[3]) {
  combineCorners<3>(field, off, fx, fy, fz, out);
}

/// interpolateCorners() of a mass-weighted step field, (w u_x, w u_y, w u_z, w) per cell: the four
/// components combined alike, then the momentum divided by the weight (StepVelocityField::build()).
inline void interpolateWeightedCorners(const float* field, const std::int32_t* off, float fx, float fy, float fz,
                                       float out[3]) {
  float v[4];
  combineCorners<4>(field, off, fx, fy, fz, v);
  for (int d = 0; d < 3; ++d) out[d] = v[d] / v[3];
}

/// Base indices and fractions of the points (x, y, z) of a block, into `s`.
inline void locateBlock(const TrilinearLocator::Constants& q, int count, const double* x, const double* y,
                        const double* z, BlockStencils& s) {
  // Plain locals only: the vectoriser gives up on loads through `this` and on per-lane arrays.
  const double ox = q.ox, oy = q.oy, oz = q.oz, ix = q.ix, iy = q.iy, iz = q.iz;
  const double lastX = q.lastX, lastY = q.lastY, lastZ = q.lastZ;
  const int maxX = q.maxX, maxY = q.maxY, maxZ = q.maxZ;
  const std::int32_t sy = q.sy, sz = q.sz;
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    int lx, ly, lz;
    s.fx[k] = float(TrilinearLocator::Constants::axis(x[k], ox, ix, lastX, maxX, lx));
    s.fy[k] = float(TrilinearLocator::Constants::axis(y[k], oy, iy, lastY, maxY, ly));
    s.fz[k] = float(TrilinearLocator::Constants::axis(z[k], oz, iz, lastZ, maxZ, lz));
    s.base[k] = lx + ly * sy + lz * sz;
  }
  if (q.plates) {
    for (int k = 0; k < count; ++k) keepStencilOnPlateSide(q.plates, s.base[k], sy, sz, s.fx[k], s.fy[k], s.fz[k]);
  }
}

/// The grid coordinates g = (x - origin) / spacing of a point along one axis, in float: the motion
/// kernel locates u_P^rec samples and takes midpoints in them (16 lanes per AVX-512 vector where
/// double positions give 8). Rounding g to float moves a point by at most 2^-24 g cells, a few 1e-8 m
/// on the paper's grid, far below the float precision of the field itself.
inline float gridCoordinate(double x, double origin, double inverseSpacing) { return float((x - origin) * inverseSpacing); }

/// Base cell along one axis and fraction of grid coordinate g (TrilinearLocator::Constants::axis() in
/// float, on g instead of x).
inline float gridAxis(float g, float last, int maxLow, int& lo) {
  float t = g - 0.5f;
  t = t > 0.0f ? t : 0.0f;  // branch-free: vectorises
  t = t < last ? t : last;
  const int i = int(t);
  lo = i < maxLow ? i : maxLow;
  return t - float(lo);
}

/// The grid's constants for gridAxis(), as plain values.
struct GridConstants {
  double ox = 0, oy = 0, oz = 0, ix = 0, iy = 0, iz = 0;  ///< origin, inverse spacing (double: g's rounding only)
  float fix = 0, fiy = 0, fiz = 0;                        ///< inverse spacing in float (midpoints)
  float lastX = 0, lastY = 0, lastZ = 0;
  int maxX = 0, maxY = 0, maxZ = 0;
  std::int32_t sy = 0, sz = 0;
  const std::uint8_t* plates = nullptr;  ///< plate faces (null: none)
  explicit GridConstants(const TrilinearLocator::Constants& q = {})
      : ox(q.ox), oy(q.oy), oz(q.oz), ix(q.ix), iy(q.iy), iz(q.iz), fix(float(q.ix)), fiy(float(q.iy)),
        fiz(float(q.iz)), lastX(float(q.lastX)), lastY(float(q.lastY)), lastZ(float(q.lastZ)), maxX(q.maxX),
        maxY(q.maxY), maxZ(q.maxZ), sy(q.sy), sz(q.sz), plates(q.plates) {}
  /// Base index and fractions of the point with grid coordinates (gx, gy, gz), kept on its side of the
  /// plates (locateGridBlock()'s arithmetic).
  std::int32_t locate(float gx, float gy, float gz, float& fx, float& fy, float& fz) const {
    int lx, ly, lz;
    fx = gridAxis(gx, lastX, maxX, lx);
    fy = gridAxis(gy, lastY, maxY, ly);
    fz = gridAxis(gz, lastZ, maxZ, lz);
    const std::int32_t base = lx + ly * sy + lz * sz;
    if (plates) keepStencilOnPlateSide(plates, base, sy, sz, fx, fy, fz);
    return base;
  }
};

/// Grid coordinates of the block's points (x, y, z).
inline void gridCoordinatesOfBlock(const GridConstants& q, int count, const double* x, const double* y,
                                   const double* z, float* gx, float* gy, float* gz) {
  const double ox = q.ox, oy = q.oy, oz = q.oz, ix = q.ix, iy = q.iy, iz = q.iz;
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    gx[k] = gridCoordinate(x[k], ox, ix), gy[k] = gridCoordinate(y[k], oy, iy), gz[k] = gridCoordinate(z[k], oz, iz);
  }
}

/// Base indices and fractions of the block's points given by grid coordinates, into `s`.
inline void locateGridBlock(const GridConstants& q, int count, const float* gx, const float* gy, const float* gz,
                            BlockStencils& s) {
  const float lastX = q.lastX, lastY = q.lastY, lastZ = q.lastZ;
  const int maxX = q.maxX, maxY = q.maxY, maxZ = q.maxZ;
  const std::int32_t sy = q.sy, sz = q.sz;
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    int lx, ly, lz;
    s.fx[k] = gridAxis(gx[k], lastX, maxX, lx);
    s.fy[k] = gridAxis(gy[k], lastY, maxY, ly);
    s.fz[k] = gridAxis(gz[k], lastZ, maxZ, lz);
    s.base[k] = lx + ly * sy + lz * sz;
  }
  if (q.plates) {
    for (int k = 0; k < count; ++k) keepStencilOnPlateSide(q.plates, s.base[k], sy, sz, s.fx[k], s.fy[k], s.fz[k]);
  }
}

/// The step field's corner offsets (in floats) and whether the AVX2 path's 32-byte corner-pair loads
/// apply: 4 floats per cell, and each corner's x-neighbour the next cell (every grid with more than one
/// layer in x).
struct CornerOffsets {
  std::int32_t off[8] = {};
  int stride = 4;  ///< floats per cell: 4 (x, y, z, w), or 3 (x, y, z) on a frame's own array
  bool pairLoads = false;
  /// The field is mass-weighted, (w u, w) per cell: samples divide by the interpolated w. Every padded
  /// field has w = 1 where it is not, so a plain field read this way gives exactly its plain samples.
  bool weighted = false;
  void set(const std::int32_t* cellOffsets, int floatsPerCell = 4) {
    stride = floatsPerCell;
    pairLoads = stride == 4;
    for (int c = 0; c < 8; ++c) off[c] = stride * cellOffsets[c];
    for (int c = 0; c < 8; c += 2) pairLoads = pairLoads && off[c + 1] == off[c] + stride;
  }
};

// Code that differs by instruction set, and its callers: one definition per kernel variant.
inline namespace RCFD_ISA_NAMESPACE {

/// (ux[k], uy[k], uz[k]) = trilinear(field; stencil of lane k) for the lanes of a block located in `s`,
/// in float. Written component by component (one store and two extracts per lane): a 4-float store per
/// lane and a transposing loop after it took twice the instructions.
inline void sampleBlock3(const float* field, const CornerOffsets& co, const BlockStencils& s, int count, float* ux,
                         float* uy, float* uz) {
#ifdef RCFD_BLOCK_SAMPLING_AVX2
  if (co.pairLoads) {
    const std::int32_t o0 = co.off[0], o2 = co.off[2], o4 = co.off[4], o6 = co.off[6];
    for (int k = 0; k < count; ++k) {
      const float* c = field + 4 * std::int64_t(s.base[k]);
      // Corners (c0 c1), (c2 c3), (c4 c5), (c6 c7), 8 floats each: a corner's x-neighbour is adjacent.
      // interpolateCorners(), two corners and all components at once: along z, then y, then x.
      const __m256 fz = _mm256_set1_ps(s.fz[k]);
      const __m256 c01 = _mm256_loadu_ps(c + o0), c23 = _mm256_loadu_ps(c + o2);
      const __m256 t01 = _mm256_fmadd_ps(fz, _mm256_sub_ps(_mm256_loadu_ps(c + o4), c01), c01);
      const __m256 t23 = _mm256_fmadd_ps(fz, _mm256_sub_ps(_mm256_loadu_ps(c + o6), c23), c23);
      const __m256 s01 = _mm256_fmadd_ps(_mm256_set1_ps(s.fy[k]), _mm256_sub_ps(t23, t01), t01);
      const __m128 s0 = _mm256_castps256_ps128(s01), s1 = _mm256_extractf128_ps(s01, 1);
      __m128 u = _mm_fmadd_ps(_mm_set1_ps(s.fx[k]), _mm_sub_ps(s1, s0), s0);
      if (co.weighted) u = _mm_div_ps(u, _mm_shuffle_ps(u, u, _MM_SHUFFLE(3, 3, 3, 3)));
      _mm_store_ss(ux + k, u);
      uy[k] = std::bit_cast<float>(_mm_extract_ps(u, 1));
      uz[k] = std::bit_cast<float>(_mm_extract_ps(u, 2));
    }
    return;
  }
#endif
  for (int k = 0; k < count; ++k) {
    float u[3];
    if (co.weighted) {
      interpolateWeightedCorners(field + co.stride * std::int64_t(s.base[k]), co.off, s.fx[k], s.fy[k], s.fz[k], u);
    } else {
      interpolateCorners(field + co.stride * std::int64_t(s.base[k]), co.off, s.fx[k], s.fy[k], s.fz[k], u);
    }
    ux[k] = u[0], uy[k] = u[1], uz[k] = u[2];
  }
}

/// u = trilinear(field; stencil) + (ax, ay, az) for the lanes of a block located in `s`.
inline void sampleBlock(const float* field, const CornerOffsets& co, const BlockStencils& s, int count,
                        const double* ax, const double* ay, const double* az, double* ux, double* uy, double* uz) {
  alignas(64) float fx[kBlock], fy[kBlock], fz[kBlock];
  sampleBlock3(field, co, s, count, fx, fy, fz);
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    ux[k] = double(fx[k]) + ax[k];
    uy[k] = double(fy[k]) + ay[k];
    uz[k] = double(fz[k]) + az[k];
  }
}

/// u = trilinear(field; stencil) + (ax, ay, az) in float for the lanes of a block located in `s`: into
/// (fx, fy, fz), and as double into (ux, uy, uz).
inline void sampleBlockFloat(const float* field, const CornerOffsets& co, const BlockStencils& s, int count,
                             const float* ax, const float* ay, const float* az, float* fx, float* fy, float* fz,
                             double* ux, double* uy, double* uz) {
  sampleBlock3(field, co, s, count, fx, fy, fz);
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    fx[k] += ax[k], fy[k] += ay[k], fz[k] += az[k];
    ux[k] = double(fx[k]), uy[k] = double(fy[k]), uz[k] = double(fz[k]);
  }
}

}  // namespace RCFD_ISA_NAMESPACE

}  // namespace rcfd::block
