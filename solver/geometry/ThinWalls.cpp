// thinWallBaffles(): plates thinner than a cell snapped to their nearest grid face (ThinWalls.hpp).

#include "geometry/ThinWalls.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace rcfd {
namespace {

/// Covered fractions within this distance of 0 or 1 are round-off (as for the open fractions).
constexpr double kSnap = 1e-12;

double overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

/// The grid face a plate thinner than a cell along axis a snaps to (index m, position x), or nothing
/// when a face lies strictly inside the plate (it closes that face itself) or the plate is off the grid.
std::optional<std::pair<int, double>> snappedFace(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int a,
                                                  const CartesianGrid& grid) {
  const auto n = grid.shape;
  const double o = grid.origin[a], h = grid.spacing[a];
  // Faces normal to a at o + m h, computed as FaceApertures does, so "strictly inside" agrees with
  // its plate test: a face strictly inside the plate is closed there already.
  const int first = std::max(0, int(std::floor((lo[a] - o) / h)) - 1);
  const int last = std::min(n[std::size_t(a)], int(std::floor((hi[a] - o) / h)) + 2);
  int below = -1;  // last face at or below lo[a]
  for (int m = first; m <= last; ++m) {
    const double x = o + m * h;
    if (x > lo[a] && x < hi[a]) return std::nullopt;
    if (x <= lo[a]) below = m;
  }
  if (below < 0 || below + 1 > n[std::size_t(a)]) return std::nullopt;
  const double mid = 0.5 * (lo[a] + hi[a]);
  const double xLow = o + below * h, xHigh = o + (below + 1) * h;
  const int m = mid - xLow <= xHigh - mid ? below : below + 1;
  return std::make_pair(m, o + m * h);
}

void bounds(const std::vector<Eigen::Vector2d>& hole, Eigen::Vector2d& lo, Eigen::Vector2d& hi) {
  lo = hole[0], hi = hole[0];
  for (const auto& v : hole) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
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
    Eigen::Vector2d lo, hi;
    bounds(hole, lo, hi);
    for (int a = 0; a < 2; ++a) {
      const int b = 1 - a;
      const auto face = snappedFace(lo, hi, a, grid);
      if (!face) continue;
      const int m = face->first;
      const double x = face->second;
      if (x > hi[a]) out.strips.push_back({a, hi[a], x, lo[b], hi[b], +1});
      if (x < lo[a]) out.strips.push_back({a, x, lo[a], lo[b], hi[b], -1});
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

std::vector<std::uint8_t> plateFacesAbove(const Apparatus& apparatus, const CartesianGrid& grid) {
  if (apparatus.holes().empty()) return {};
  const BaffleFaces baffles = thinWallBaffles(apparatus, grid);
  std::vector<std::uint8_t> out(std::size_t(grid.cellCount()), 0);
  for (int k = 0; k < grid.shape[2]; ++k)
    for (int j = 0; j < grid.shape[1]; ++j)
      for (int i = 0; i < grid.shape[0]; ++i) {
        std::uint8_t& m = out[std::size_t(grid.flatIndex(i, j, k))];
        const std::array<int, 3> ijk{i, j, k};
        if (i + 1 < grid.shape[0] && plateSeparates(apparatus, grid, baffles, ijk, 0, +1)) m |= kPlateAboveX;
        if (j + 1 < grid.shape[1] && plateSeparates(apparatus, grid, baffles, ijk, 1, +1)) m |= kPlateAboveY;
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
    Eigen::Vector2d lo, hi;
    bounds(hole, lo, hi);
    if (plane >= lo[d] && plane <= hi[d] && from >= lo[across] - slack && to <= hi[across] + slack) return true;
  }
  return false;
}

}  // namespace rcfd
