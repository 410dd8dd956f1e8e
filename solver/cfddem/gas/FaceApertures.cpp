// computeFaceApertures(): exact open-area fractions of grid faces (declared in FaceApertures.hpp).

#include "cfddem/gas/FaceApertures.hpp"

#include <algorithm>
#include <cmath>

namespace rcfd::gas {
namespace {

using Eigen::Vector2d;

/// Apertures within this distance of 0 or 1 are round-off and are snapped (as for the open fractions).
constexpr double kSnap = 1e-12;
double snap(double f) {
  if (f < kSnap) return 0.0;
  if (f > 1.0 - kSnap) return 1.0;
  return f;
}

double overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

/// Open length of the grid-boundary segment a->b: its overlap with the inlet and outlet edges.
double boundaryOpenLength(const Apparatus& apparatus, const Vector2d& a, const Vector2d& b) {
  const double tol = apparatus.boundaryTolerance();
  double open = 0.0;
  for (const auto& e : apparatus.sectionEdges()) {
    if (e.kind != BoundaryKind::Inlet && e.kind != BoundaryKind::Outlet) continue;
    // Both are horizontal (the slot at y = 0, the top); a face counts when it lies on the edge's line.
    if (std::abs(e.a.y() - e.b.y()) > tol || std::abs(a.y() - e.a.y()) > tol || std::abs(a.y() - b.y()) > tol)
      continue;
    open += overlap(std::min(a.x(), b.x()), std::max(a.x(), b.x()), std::min(e.a.x(), e.b.x()),
                    std::max(e.a.x(), e.b.x()));
  }
  return open;
}

}  // namespace

double openSegmentLength(const Apparatus& apparatus, const Vector2d& a, const Vector2d& b) {
  // Clip the parameter range [0, 1] of a + t (b - a) against the convex outline's half-planes.
  const auto& poly = apparatus.outline();
  const Vector2d d = b - a;
  double t0 = 0.0, t1 = 1.0;
  for (std::size_t n = 0; n < poly.size() && t0 < t1; ++n) {
    const Vector2d& p = poly[n];
    const Vector2d& q = poly[(n + 1) % poly.size()];
    const Vector2d inward(-(q - p).y(), (q - p).x());  // counter-clockwise: the inside is on the left
    const double fa = inward.dot(a - p), fd = inward.dot(d);
    // Scale-aware zero: a segment on the edge's line is inside.
    const double eps = 1e-12 * inward.norm() * (d.norm() + (a - p).norm());
    if (std::abs(fd) <= eps) {
      if (fa < -eps) t1 = t0 - 1.0;  // parallel and outside
      continue;
    }
    const double t = -fa / fd;
    if (fd > 0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
  }
  if (t1 <= t0) return 0.0;
  const double len = d.norm();
  double open = (t1 - t0) * len;
  // Subtract the plates (axis-aligned rectangles): the segment is axis-aligned too.
  const int along = std::abs(d.x()) >= std::abs(d.y()) ? 0 : 1, across = 1 - along;
  const double lo = std::min(a[along] + t0 * d[along], a[along] + t1 * d[along]);
  const double hi = std::max(a[along] + t0 * d[along], a[along] + t1 * d[along]);
  for (const auto& hole : apparatus.holes()) {
    double h0 = hole[0][along], h1 = h0, c0 = hole[0][across], c1 = c0;
    for (const auto& v : hole) {
      h0 = std::min(h0, v[along]), h1 = std::max(h1, v[along]);
      c0 = std::min(c0, v[across]), c1 = std::max(c1, v[across]);
    }
    // Strictly inside across: a face on the plate's surface is open (the plate's cells are closed).
    if (a[across] > c0 && a[across] < c1) open -= overlap(lo, hi, h0, h1);
  }
  return std::max(0.0, open);
}

FaceApertures computeFaceApertures(const Apparatus& apparatus, const CartesianGrid& grid) {
  FaceApertures out;
  const auto n = grid.shape;
  const Eigen::Vector3d h = grid.spacing, o = grid.origin;
  const double depth = apparatus.depth();
  for (int d = 0; d < 3; ++d) {
    auto& s = out.shape[std::size_t(d)];
    s = n;
    s[std::size_t(d)] += 1;
    out.open[std::size_t(d)].assign(std::size_t(s[0]) * s[1] * s[2], 0.0);
  }
  // Fraction of each z-layer inside [0, depth] (1 for the grids of makeGrid()).
  std::vector<double> zFraction(static_cast<std::size_t>(n[2]));
  for (int k = 0; k < n[2]; ++k)
    zFraction[std::size_t(k)] = snap(overlap(o.z() + k * h.z(), o.z() + (k + 1) * h.z(), 0.0, depth) / h.z());

  out.baffles = thinWallBaffles(apparatus, grid);
  // x-faces: vertical segments; y-faces: horizontal segments. One x-y section, repeated along z.
  for (int d = 0; d < 2; ++d) {
    const auto s = out.shape[std::size_t(d)];
    std::vector<double> section(std::size_t(s[0]) * s[1]);
#pragma omp parallel for schedule(static)
    for (int j = 0; j < s[1]; ++j) {
      for (int i = 0; i < s[0]; ++i) {
        const Vector2d a(o.x() + i * h.x(), o.y() + j * h.y());
        const Vector2d b = d == 0 ? Vector2d(a.x(), a.y() + h.y()) : Vector2d(a.x() + h.x(), a.y());
        const bool onBoundary = d == 0 ? (i == 0 || i == s[0] - 1) : (j == 0 || j == s[1] - 1);
        const double len = onBoundary ? boundaryOpenLength(apparatus, a, b) : openSegmentLength(apparatus, a, b);
        double f = snap(len / (b - a).norm());
        // A baffle closes its share of the face (the same in every z-layer: the plates span the depth).
        if (!out.baffles.covered[std::size_t(d)].empty())
          f = snap(std::max(0.0, f - out.baffles.covered[std::size_t(d)][out.baffles.index(d, i, j, 0)]));
        section[std::size_t(j) * s[0] + i] = f;
      }
    }
    for (int k = 0; k < s[2]; ++k)
      for (std::size_t ij = 0; ij < section.size(); ++ij)
        out.open[std::size_t(d)][std::size_t(k) * section.size() + ij] = snap(section[ij] * zFraction[std::size_t(k)]);
  }
  // z-faces: interior ones have the open area of the section cell; z = 0 and z = depth are walls.
  const auto cells = openFractions(apparatus, grid);
  const auto s = out.shape[2];
  for (int k = 1; k < s[2] - 1; ++k)
    for (int j = 0; j < s[1]; ++j)
      for (int i = 0; i < s[0]; ++i) {
        // Both neighbours share the section; the z-overlap does not matter for a face inside [0, depth].
        const double below = cells[std::size_t(grid.flatIndex(i, j, k - 1))] / std::max(zFraction[std::size_t(k - 1)], 1e-300);
        out.open[2][(std::size_t(k) * s[1] + j) * s[0] + i] = zFraction[std::size_t(k - 1)] > 0 && zFraction[std::size_t(k)] > 0 ? snap(below) : 0.0;
      }
  return out;
}

}  // namespace rcfd::gas
