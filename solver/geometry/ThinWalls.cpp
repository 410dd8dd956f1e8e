// thinWallBaffles(): plates thinner than a cell snapped to their nearest grid face (ThinWalls.hpp).

#include "geometry/ThinWalls.hpp"

#include <algorithm>
#include <cmath>

namespace rcfd {
namespace {

/// Covered fractions within this distance of 0 or 1 are round-off (as for the open fractions).
constexpr double kSnap = 1e-12;

double overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

}  // namespace

BaffleFaces thinWallBaffles(const Apparatus& apparatus, const CartesianGrid& grid) {
  BaffleFaces out;
  const auto n = grid.shape;
  const Eigen::Vector3d h = grid.spacing, o = grid.origin;
  for (int d = 0; d < 3; ++d) {
    out.shape[std::size_t(d)] = n;
    out.shape[std::size_t(d)][std::size_t(d)] += 1;
  }
  for (const auto& hole : apparatus.holes()) {
    Eigen::Vector2d lo = hole[0], hi = hole[0];
    for (const auto& v : hole) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    for (int a = 0; a < 2; ++a) {
      const int b = 1 - a;
      // Faces normal to a at o + m h, computed as FaceApertures does, so "strictly inside" agrees with
      // its plate test: a face strictly inside the plate is closed there already.
      const int first = std::max(0, int(std::floor((lo[a] - o[a]) / h[a])) - 1);
      const int last = std::min(n[std::size_t(a)], int(std::floor((hi[a] - o[a]) / h[a])) + 2);
      int below = -1;  // last face at or below lo[a]
      bool faceInside = false;
      for (int m = first; m <= last; ++m) {
        const double x = o[a] + m * h[a];
        if (x > lo[a] && x < hi[a]) faceInside = true;
        if (x <= lo[a]) below = m;
      }
      if (faceInside || below < 0 || below + 1 > n[std::size_t(a)]) continue;
      const double mid = 0.5 * (lo[a] + hi[a]);
      const double xLow = o[a] + below * h[a], xHigh = o[a] + (below + 1) * h[a];
      const int m = mid - xLow <= xHigh - mid ? below : below + 1;
      // Cover the face column m over the plate's extent along b, in every z-layer.
      auto& cov = out.covered[std::size_t(a)];
      const auto& s = out.shape[std::size_t(a)];
      if (cov.empty()) cov.assign(std::size_t(s[0]) * s[1] * s[2], 0.0);
      for (int r = 0; r < n[std::size_t(b)]; ++r) {
        const double r0 = o[b] + r * h[b];
        const double f = overlap(r0, r0 + h[b], lo[b], hi[b]) / h[b];
        if (f < kSnap) continue;
        for (int k = 0; k < s[2]; ++k) {
          const std::size_t idx = a == 0 ? out.index(0, m, r, k) : out.index(1, r, m, k);
          double& c = cov[idx];
          c = std::min(1.0, c + f);
          if (c > 1.0 - kSnap) c = 1.0;
        }
      }
    }
  }
  return out;
}

bool plateSeparates(const Apparatus& apparatus, const CartesianGrid& grid, const BaffleFaces& baffles,
                    const std::array<int, 3>& ijk, int d, int side) {
  if (d > 1) return false;
  auto face = ijk;
  face[std::size_t(d)] += side > 0 ? 1 : 0;  // faces carry the index of the cell above them
  if (baffles.closes(d, face[0], face[1], face[2])) return true;
  // A plate closes the face when the face's plane lies within its thickness and the plate covers the
  // face's whole extent across (a face the plate only cuts stays open, as a partly covered baffle).
  const int across = 1 - d;
  const double plane = grid.origin[d] + face[std::size_t(d)] * grid.spacing[d];
  const double from = grid.origin[across] + ijk[std::size_t(across)] * grid.spacing[across];
  const double to = from + grid.spacing[across];
  const double slack = kSnap * grid.spacing[across];
  for (const auto& hole : apparatus.holes()) {
    Eigen::Vector2d lo = hole[0], hi = hole[0];
    for (const auto& v : hole) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    if (plane >= lo[d] && plane <= hi[d] && from >= lo[across] - slack && to <= hi[across] + slack) return true;
  }
  return false;
}

}  // namespace rcfd
