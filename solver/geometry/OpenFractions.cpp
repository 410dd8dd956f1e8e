// openFractions(): exact open volume fraction of every grid cell, from clipping the apparatus's
// cross-section against the cell (declared in Apparatus.hpp).

#include <algorithm>
#include <array>
#include <cmath>

#include "geometry/Apparatus.hpp"

namespace rcfd {
namespace {

using Eigen::Vector2d;

/// A small fixed-capacity polygon: a convex n-gon clipped by 4 half-planes has at most n + 4 vertices.
struct SmallPolygon {
  static constexpr int kCapacity = 32;
  std::array<Vector2d, kCapacity> v;
  int n = 0;
  void push(const Vector2d& p) { v[std::size_t(n++)] = p; }
};

/// Sutherland-Hodgman: keeps the part of `in` with sign * (p[axis] - value) >= 0.
void clipAxis(const SmallPolygon& in, SmallPolygon& out, int axis, double value, double sign) {
  out.n = 0;
  for (int i = 0; i < in.n; ++i) {
    const Vector2d& p = in.v[std::size_t(i)];
    const Vector2d& q = in.v[std::size_t((i + 1) % in.n)];
    const double dp = sign * (p[axis] - value), dq = sign * (q[axis] - value);
    if (dp >= 0.0) out.push(p);
    if ((dp >= 0.0) != (dq >= 0.0)) {
      const double t = dp / (dp - dq);
      Vector2d r = p + t * (q - p);
      r[axis] = value;  // exactly on the clip line, no round-off drift
      out.push(r);
    }
  }
}

/// Shoelace area, with coordinates taken relative to `origin` (the cell corner): without the shift
/// the products of metre-sized coordinates cancel and a millimetre cell loses ~1e-12 of its area.
double area(const SmallPolygon& poly, const Vector2d& origin) {
  double twice = 0.0;
  for (int i = 0; i < poly.n; ++i) {
    const Vector2d p = poly.v[std::size_t(i)] - origin;
    const Vector2d q = poly.v[std::size_t((i + 1) % poly.n)] - origin;
    twice += p.x() * q.y() - p.y() * q.x();
  }
  return 0.5 * twice;
}

/// Open fractions within this distance of 0 or 1 are round-off and are snapped, so fully closed and
/// fully open cells are exactly 0 and 1.
constexpr double kSnap = 1e-12;
double snap(double f) {
  if (f < kSnap) return 0.0;
  if (f > 1.0 - kSnap) return 1.0;
  return f;
}

/// Area of the convex outline inside the rectangle [lo, hi].
double clippedArea(const std::vector<Vector2d>& outline, const Vector2d& lo, const Vector2d& hi) {
  SmallPolygon a, b;
  for (const auto& p : outline) a.push(p);
  clipAxis(a, b, 0, lo.x(), 1.0);
  clipAxis(b, a, 0, hi.x(), -1.0);
  clipAxis(a, b, 1, lo.y(), 1.0);
  clipAxis(b, a, 1, hi.y(), -1.0);
  return a.n < 3 ? 0.0 : area(a, lo);
}

double overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

}  // namespace

std::vector<double> openFractions(const Apparatus& apparatus, const CartesianGrid& grid) {
  const int nx = grid.shape[0], ny = grid.shape[1], nz = grid.shape[2];
  const double dx = grid.spacing.x(), dy = grid.spacing.y(), dz = grid.spacing.z();
  const auto& outline = apparatus.outline();

  // The cross-section's open fraction per (i, j): outline area in the cell minus the plates' area.
  std::vector<double> section(std::size_t(nx) * ny);
#pragma omp parallel for schedule(static)
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const Vector2d lo(grid.origin.x() + i * dx, grid.origin.y() + j * dy);
      const Vector2d hi(grid.origin.x() + (i + 1) * dx, grid.origin.y() + (j + 1) * dy);
      double open = clippedArea(outline, lo, hi);
      for (const auto& hole : apparatus.holes()) {
        double hx0 = hole[0].x(), hx1 = hole[0].x(), hy0 = hole[0].y(), hy1 = hole[0].y();
        for (const auto& p : hole) {
          hx0 = std::min(hx0, p.x()), hx1 = std::max(hx1, p.x());
          hy0 = std::min(hy0, p.y()), hy1 = std::max(hy1, p.y());
        }
        open -= overlap(lo.x(), hi.x(), hx0, hx1) * overlap(lo.y(), hi.y(), hy0, hy1);
      }
      // Only round-off can push the fraction out of [0, 1] here (clipping is exact).
      section[std::size_t(j) * nx + i] = snap(open / (dx * dy));
    }
  }

  std::vector<double> fractions(std::size_t(grid.cellCount()));
  for (int k = 0; k < nz; ++k) {
    const double z0 = grid.origin.z() + k * dz;
    const double zFraction = snap(overlap(z0, z0 + dz, 0.0, apparatus.depth()) / dz);
    for (std::size_t ij = 0; ij < section.size(); ++ij)
      fractions[std::size_t(k) * section.size() + ij] = snap(section[ij] * zFraction);
  }
  return fractions;
}

}  // namespace rcfd
