#include "cfddem/NeighbourList.hpp"
#include "cfddem/DemParallel.hpp"

#include <algorithm>
#include <cmath>
#include <omp.h>

#include "core/Errors.hpp"

namespace rcfd {

using Eigen::Vector3d;

bool NeighbourList::needsRebuild(const DemParticles& p) const {
  if (x_at_build_.size() != p.size()) return true;
  const double limit2 = 0.25 * skin_ * skin_;
  const long n = static_cast<long>(p.size());
  int moved = 0;
#pragma omp parallel for reduction(| : moved) schedule(static) if (n >= kDemParallelMinParticles)
  for (long i = 0; i < n; ++i) moved |= (p.x[i] - x_at_build_[i]).squaredNorm() > limit2 ? 1 : 0;
  return moved != 0;
}

void NeighbourList::permute(const std::vector<std::size_t>& perm) {
  const std::size_t n = perm.size();
  if (row_start.size() != n + 1) return;
  std::vector<Index> inv(n);
  for (std::size_t k = 0; k < n; ++k) inv[perm[k]] = static_cast<Index>(k);
  struct Entry {
    Index i, j;
    Vector3d shear;
  };
  std::vector<Entry> e;
  e.reserve(j.size());
  for (std::size_t i = 0; i < n; ++i)
    for (Index q = row_start[i]; q < row_start[i + 1]; ++q) {
      Index a = inv[i], b = inv[j[q]];
      // The history is the first body's displacement relative to the second: swap -> negate.
      if (a < b) e.push_back({a, b, shear[q]});
      else e.push_back({b, a, -shear[q]});
    }
  std::sort(e.begin(), e.end(), [](const Entry& x, const Entry& y) {
    return x.i != y.i ? x.i < y.i : x.j < y.j;
  });
  std::fill(row_start.begin(), row_start.end(), 0);
  for (std::size_t q = 0; q < e.size(); ++q) {
    ++row_start[e[q].i + 1];
    j[q] = e[q].j;
    shear[q] = e[q].shear;
  }
  for (std::size_t i = 0; i < n; ++i) row_start[i + 1] += row_start[i];
  x_at_build_.clear();  // forces a rebuild
}

void NeighbourList::build(const DemParticles& p, const DemWalls& walls) {
  const long n = static_cast<long>(p.size());
  ++builds_;
  // Keep the old list to carry the tangential history over.
  std::vector<Index> old_start = std::move(row_start), old_j = std::move(j);
  std::vector<Vector3d> old_shear = std::move(shear);
  // Particles are only ever appended, so old rows keep their index.
  const long old_n = old_start.empty() ? 0 : static_cast<long>(old_start.size()) - 1;

  x_at_build_ = p.x;
  row_start.assign(n + 1, 0);
  wall_start.assign(n + 1, 0);
  if (n == 0) {
    j.clear(); shear.clear(); col_start.assign(1, 0); col_pair.clear(); wall_id.clear();
    return;
  }

  // Linked cells of edge >= the largest interaction distance 2 r_max + skin.
  Vector3d lo = p.x[0], hi = p.x[0];
  double r_max = 0.0;
  for (long i = 0; i < n; ++i) {
    lo = lo.cwiseMin(p.x[i]);
    hi = hi.cwiseMax(p.x[i]);
    r_max = std::max(r_max, p.radius[i]);
  }
  if (!lo.allFinite() || !hi.allFinite())
    throw RunError("DEM: a particle position is not finite (the time step is too large or a "
                   "contact exploded)");
  // The cells are as small as the interaction distance allows, so the 27-cell stencil holds few
  // candidates: a bed that fills a small part of its bounding box (a fountain above it, a tall
  // chamber) still has about 2 parcels per cell where it is dense. Only when the box is so large that
  // the cell offsets would not fit kMaxCellsPerParticle per particle (particles escaped far apart) are
  // the cells made coarser, by the factor that fits, which stays correct and only costs candidates.
  double cell = 2.0 * r_max + skin_;
  long nc[3];
  const double maxCells = double(kMaxCellsPerParticle) * double(n) + 4096.0;
  for (;;) {
    double total = 1.0;
    for (int a = 0; a < 3; ++a) {
      nc[a] = std::max(1L, static_cast<long>(std::min((hi[a] - lo[a]) / cell, 1e6)));
      total *= double(nc[a]);
    }
    if (total <= maxCells) break;
    cell *= std::max(1.01, std::cbrt(total / maxCells));
  }
  const Vector3d inv_cell(nc[0] / std::max(hi[0] - lo[0], 1e-300), nc[1] / std::max(hi[1] - lo[1], 1e-300),
                          nc[2] / std::max(hi[2] - lo[2], 1e-300));
  auto cellOf = [&](const Vector3d& x, long c[3]) {
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(static_cast<long>((x[a] - lo[a]) * inv_cell[a]), 0L, nc[a] - 1);
  };
  const long ncell = nc[0] * nc[1] * nc[2];
  cell_start_.assign(ncell + 1, 0);
  cell_particles_.resize(n);
  std::vector<Index> cell_of(n);
  for (long i = 0; i < n; ++i) {
    long c[3];
    cellOf(p.x[i], c);
    cell_of[i] = static_cast<Index>((c[2] * nc[1] + c[1]) * nc[0] + c[0]);
    ++cell_start_[cell_of[i] + 1];
  }
  for (long c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  {
    std::vector<Index> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (long i = 0; i < n; ++i) cell_particles_[fill[cell_of[i]]++] = static_cast<Index>(i);
  }

  // Two passes over the same stencil: count, then fill (parallel, results independent of threads).
  auto visit = [&](long i, auto&& emit) {
    long c[3];
    cellOf(p.x[i], c);
    const Vector3d xi = p.x[i];
    const double ri = p.radius[i];
    for (long dz = -1; dz <= 1; ++dz) {
      const long z = c[2] + dz;
      if (z < 0 || z >= nc[2]) continue;
      for (long dy = -1; dy <= 1; ++dy) {
        const long y = c[1] + dy;
        if (y < 0 || y >= nc[1]) continue;
        for (long dx = -1; dx <= 1; ++dx) {
          const long x = c[0] + dx;
          if (x < 0 || x >= nc[0]) continue;
          const long cc = (z * nc[1] + y) * nc[0] + x;
          for (Index q = cell_start_[cc]; q < cell_start_[cc + 1]; ++q) {
            const Index k = cell_particles_[q];
            if (k <= static_cast<Index>(i)) continue;
            const double cut = ri + p.radius[k] + skin_;
            if ((p.x[k] - xi).squaredNorm() < cut * cut) emit(k);
          }
        }
      }
    }
  };
  // One pass over the stencil in fixed blocks of rows, each into its own buffer, then the buffers
  // joined in block order: the same list for any number of threads.
  constexpr long kRowsPerBlock = 256;
  const long blocks = (n + kRowsPerBlock - 1) / kRowsPerBlock;
  std::vector<std::vector<Index>> blockPairs(static_cast<std::size_t>(blocks)), blockWalls(static_cast<std::size_t>(blocks));
#pragma omp parallel for schedule(dynamic, 1) if (n >= kDemParallelMinParticles)
  for (long b = 0; b < blocks; ++b) {
    auto& pairs = blockPairs[std::size_t(b)];
    auto& wallsNear = blockWalls[std::size_t(b)];
    for (long i = b * kRowsPerBlock; i < std::min(n, (b + 1) * kRowsPerBlock); ++i) {
      const std::size_t first = pairs.size();
      visit(i, [&](Index k) { pairs.push_back(k); });
      // Sorted rows: a fixed order whatever the cell layout, and a cheap history look-up.
      std::sort(pairs.begin() + std::ptrdiff_t(first), pairs.end());
      row_start[i + 1] = static_cast<Index>(pairs.size() - first);
      const std::size_t firstWall = wallsNear.size();
      for (std::size_t k = 0; k < walls.size(); ++k)
        if (walls.distanceTo(k, p.x[i]) < p.radius[i] + skin_) wallsNear.push_back(static_cast<Index>(k));
      wall_start[i + 1] = static_cast<Index>(wallsNear.size() - firstWall);
    }
  }
  for (long i = 0; i < n; ++i) {
    row_start[i + 1] += row_start[i];
    wall_start[i + 1] += wall_start[i];
  }
  j.resize(row_start[n]);
  shear.assign(row_start[n], Vector3d::Zero());
  wall_id.resize(wall_start[n]);
#pragma omp parallel for schedule(dynamic, 1) if (n >= kDemParallelMinParticles)
  for (long b = 0; b < blocks; ++b) {
    const long i0 = b * kRowsPerBlock, i1 = std::min(n, (b + 1) * kRowsPerBlock);
    std::copy(blockPairs[std::size_t(b)].begin(), blockPairs[std::size_t(b)].end(), j.begin() + row_start[i0]);
    std::copy(blockWalls[std::size_t(b)].begin(), blockWalls[std::size_t(b)].end(), wall_id.begin() + wall_start[i0]);
    for (long i = i0; i < std::min(i1, old_n); ++i) {
      Index o = old_start[i];
      const Index oe = old_start[i + 1];
      for (Index q = row_start[i]; q < row_start[i + 1]; ++q) {
        while (o < oe && old_j[o] < j[q]) ++o;
        if (o < oe && old_j[o] == j[q]) shear[q] = old_shear[o];
      }
    }
  }

  // Transpose: counting sort of the pairs by their second member, in pair order.
  col_start.assign(n + 1, 0);
  for (Index q : j) ++col_start[q + 1];
  for (long i = 0; i < n; ++i) col_start[i + 1] += col_start[i];
  col_pair.resize(j.size());
  std::vector<Index> fill(col_start.begin(), col_start.end() - 1);
  for (Index q = 0; q < j.size(); ++q) col_pair[fill[j[q]]++] = q;
}

}  // namespace rcfd
