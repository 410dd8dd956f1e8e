#pragma once
/// \file Trilinear.hpp
/// Trilinear interpolation between cell centres, split for the tracer hot loop into locating a point
/// (one base index and three fractions) and combining the 8 corner values of that base. The 8 corners
/// are the base plus fixed offsets, so a stencil needs one index computation (the motion kernel's
/// float combination of the corners is block::interpolateCorners).
/// Beyond the outermost centres values are extrapolated as constants (the fractions are clamped).
/// Across a plate thinner than a cell (a baffle face, geometry/ThinWalls.hpp) no value is taken from
/// the other side: given the grid's plate faces, a stencil whose two centres along x or y a plate
/// separates takes its own side's centre (keepStencilOnPlateSide).

#include <algorithm>
#include <array>
#include <cstdint>

#include "geometry/CartesianGrid.hpp"
#include "geometry/ThinWalls.hpp"

namespace rcfd {

/// The stencil (base, fractions) of a point kept on its side of the plates: along x (or y), when a
/// plate closes the face between the stencil's two centres in the point's own row (layer), the fraction
/// becomes that of the point's own centre, 0 or 1: the value up to the plate is its own side's, held
/// constant, as beyond the outermost centres. The point's side is that of its cell (fraction >= 1/2);
/// in the strip between a plate and its baffle face (geometry/ThinWalls.hpp) that is the baffle's near
/// side.
template <class T>
inline void keepStencilOnPlateSide(const std::uint8_t* plates, std::int32_t base, std::int32_t sy, std::int32_t sz,
                                   T& fx, T& fy, T fz) {
  const std::int32_t ox = fx >= T(0.5), oy = fy >= T(0.5), oz = fz >= T(0.5);
  if (plates[base + oy * sy + oz * sz] & kPlateAboveX) fx = T(ox);
  if (plates[base + ox + oz * sz] & kPlateAboveY) fy = T(oy);
}

/// A point's place among the cell centres: flat index of the low corner of the 2x2x2 block of centres
/// around it and the fractions along x, y, z within that block, each in [0, 1].
struct TrilinearStencil {
  std::int64_t base = 0;
  double f[3] = {0.0, 0.0, 0.0};
};

/// The grid in the form the hot loop needs: inverse spacing, clamping bounds and corner offsets.
class TrilinearLocator {
 public:
  /// plates: per cell the plate faces (plateFacesAbove, geometry/ThinWalls.hpp), or null for none; kept
  /// by the caller.
  explicit TrilinearLocator(const CartesianGrid& grid, const std::uint8_t* plates = nullptr) : plates_(plates) {
    std::int64_t stride = 1;
    std::int64_t step[3];
    for (int d = 0; d < 3; ++d) {
      const int n = grid.shape[d];
      origin_[d] = grid.origin[d];
      inv_[d] = 1.0 / grid.spacing[d];
      last_[d] = double(n - 1);
      maxLow_[d] = std::max(n - 2, 0);
      stride32_[d] = std::int32_t(stride);
      step[d] = n > 1 ? stride : 0;  // a single layer: both corners are the same cell
      stride *= n;
    }
    for (int c = 0; c < 8; ++c) {
      offsets_[c] = (c & 1) * step[0] + ((c >> 1) & 1) * step[1] + (c >> 2) * step[2];
      offsets32_[std::size_t(c)] = std::int32_t(offsets_[c]);
    }
  }

  TrilinearStencil locate(const Eigen::Vector3d& p) const {
    TrilinearStencil s;
    std::int32_t base = 0;
    locate(p.x(), p.y(), p.z(), base, s.f[0], s.f[1], s.f[2]);  // kept on its side of the plates
    s.base = base;
    return s;
  }

  /// The locator's numbers as a plain value, for loops over many points that the compiler vectorises
  /// (`#pragma omp simd`): Constants::locate is the arithmetic of locate() without the plates, which
  /// such loops apply after it (keepOnPlateSide), so both give the same result.
  struct Constants {
    double ox, oy, oz, ix, iy, iz, lastX, lastY, lastZ;
    int maxX, maxY, maxZ;
    std::int32_t sy, sz;
    const std::uint8_t* plates = nullptr;  ///< the locator's plate faces (null: none)
    static double axis(double x, double o, double inv, double last, int maxLow, int& lo) {
      double t = (x - o) * inv - 0.5;
      t = t > 0.0 ? t : 0.0;  // not std::clamp: the branch-free form vectorises
      t = t < last ? t : last;
      const int i = int(t);
      lo = i < maxLow ? i : maxLow;
      return t - double(lo);
    }
    /// Base index (flat cell index of the low corner) and fractions of the point (x, y, z).
    std::int32_t locate(double x, double y, double z, double& fx, double& fy, double& fz) const {
      int lx, ly, lz;
      fx = axis(x, ox, ix, lastX, maxX, lx);
      fy = axis(y, oy, iy, lastY, maxY, ly);
      fz = axis(z, oz, iz, lastZ, maxZ, lz);
      return lx + ly * sy + lz * sz;
    }
    /// locate()'s stencil kept on its side of the plates (a no-op without plates).
    void keepOnPlateSide(std::int32_t base, double& fx, double& fy, double fz) const {
      if (plates) keepStencilOnPlateSide(plates, base, sy, sz, fx, fy, fz);
    }
  };
  Constants constants() const {
    return {origin_[0], origin_[1], origin_[2], inv_[0],    inv_[1],      inv_[2],      last_[0], last_[1],
            last_[2],   maxLow_[0], maxLow_[1], maxLow_[2], stride32_[1], stride32_[2], plates_};
  }

  void locate(double x, double y, double z, std::int32_t& base, double& fx, double& fy, double& fz) const {
    const Constants q = constants();
    base = q.locate(x, y, z, fx, fy, fz);
    q.keepOnPlateSide(base, fx, fy, fz);
  }

  /// Offset (in cells) of corner c from the base; bit 0 of c is x, bit 1 y, bit 2 z.
  std::int64_t offset(int c) const { return offsets_[c]; }
  const std::int32_t* offsets32() const { return offsets32_.data(); }

 private:

  const std::uint8_t* plates_ = nullptr;
  double origin_[3], inv_[3], last_[3];
  int maxLow_[3];
  std::int32_t stride32_[3];  // tracer cells are int32 throughout (TracerContext::tracerCell)
  std::array<std::int64_t, 8> offsets_{};
  std::array<std::int32_t, 8> offsets32_{};
};

/// Trilinear combination of 8 corner values (corner c: bit 0 x, bit 1 y, bit 2 z) by successive linear
/// interpolation along x, y, then z. Exact for a uniform field (a + f (a - a) = a), which keeps uniform
/// flow displacements exact.
template <class T>
T trilinear(const T* c, double fx, double fy, double fz) {
  const T x00 = c[0] + fx * (c[1] - c[0]);
  const T x10 = c[2] + fx * (c[3] - c[2]);
  const T x01 = c[4] + fx * (c[5] - c[4]);
  const T x11 = c[6] + fx * (c[7] - c[6]);
  const T y0 = x00 + fy * (x10 - x00);
  const T y1 = x01 + fy * (x11 - x01);
  return y0 + fz * (y1 - y0);
}
template <class T>
T trilinear(const T* c, const double* f) {
  return trilinear(c, f[0], f[1], f[2]);
}

}  // namespace rcfd
