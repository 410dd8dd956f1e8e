#include "cfddem/NeighbourList.hpp"
#include "cfddem/DemParallel.hpp"

#include <algorithm>
#include <array>
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
    // y slowest, then z, then x: the order sortParticles() keeps the particles in, so a block of cells
    // reads neighbouring memory.
    cell_of[i] = static_cast<Index>((c[1] * nc[2] + c[2]) * nc[0] + c[0]);
    ++cell_start_[cell_of[i] + 1];
  }
  for (long c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  {
    std::vector<Index> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (long i = 0; i < n; ++i) cell_particles_[fill[cell_of[i]]++] = static_cast<Index>(i);
  }

  // Each pair is met once: a particle meets the particles after it in its own cell and every particle of
  // the 13 neighbour cells after its cell (the half of the 26 whose first non-zero offset, in the cells'
  // y, z, x order, is positive). Cells go in fixed blocks, each block's pairs (lower index first) into a buffer
  // of its own.
  static constexpr long kForward[13][3] = {{0, 0, 1},  {0, 1, -1}, {0, 1, 0},  {0, 1, 1},  {1, -1, -1},
                                           {1, -1, 0}, {1, -1, 1}, {1, 0, -1}, {1, 0, 0},  {1, 0, 1},
                                           {1, 1, -1}, {1, 1, 0},  {1, 1, 1}};
  constexpr long kCellsPerBlock = 512;
  const long cellBlocks = (ncell + kCellsPerBlock - 1) / kCellsPerBlock;
  std::vector<std::vector<std::array<Index, 2>>> found(static_cast<std::size_t>(cellBlocks));
  const bool parallel = n >= kDemParallelMinParticles;
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
  for (long b = 0; b < cellBlocks; ++b) {
    auto& out = found[std::size_t(b)];
    for (long cc = b * kCellsPerBlock; cc < std::min(ncell, (b + 1) * kCellsPerBlock); ++cc) {
      const Index first = cell_start_[cc], last = cell_start_[cc + 1];
      if (first == last) continue;
      const long x = cc % nc[0], z = (cc / nc[0]) % nc[2], y = cc / (nc[0] * nc[2]);
      for (Index qa = first; qa < last; ++qa) {
        const Index a = cell_particles_[qa];
        const Vector3d xa = p.x[a];
        const double ra = p.radius[a];
        auto meet = [&](Index k) {
          const double cut = ra + p.radius[k] + skin_;
          if ((p.x[k] - xa).squaredNorm() < cut * cut) out.push_back(a < k ? std::array<Index, 2>{a, k} : std::array<Index, 2>{k, a});
        };
        for (Index qb = qa + 1; qb < last; ++qb) meet(cell_particles_[qb]);
        for (const auto& o : kForward) {
          const long yy = y + o[0], zz = z + o[1], xx = x + o[2];
          if (yy >= nc[1] || zz < 0 || zz >= nc[2] || xx < 0 || xx >= nc[0]) continue;
          const long nb = (yy * nc[2] + zz) * nc[0] + xx;
          for (Index qb = cell_start_[nb]; qb < cell_start_[nb + 1]; ++qb) meet(cell_particles_[qb]);
        }
      }
    }
  }
  // Rows: the pairs counted by their lower index (each thread a contiguous range of blocks), placed,
  // and each row sorted: a fixed order whatever the cells and threads, and a cheap history look-up.
  const int teams = parallel ? omp_get_max_threads() : 1;
  std::vector<Index> counts(std::size_t(teams) * std::size_t(n), 0);
  std::vector<Index> next_j;
#pragma omp parallel num_threads(teams) if (teams > 1)
  {
    // The team may be smaller than asked (inside another parallel region): its own size splits the work.
    const int team = omp_get_num_threads(), t = omp_get_thread_num();
    const long b0 = cellBlocks * t / team, b1 = cellBlocks * (t + 1) / team;
    Index* mine = counts.data() + std::size_t(t) * std::size_t(n);
    for (long b = b0; b < b1; ++b)
      for (const auto& pr : found[std::size_t(b)]) ++mine[pr[0]];
#pragma omp barrier
#pragma omp single
    {
      Index running = 0;
      for (long i = 0; i < n; ++i) {
        row_start[i] = running;
        for (int u = 0; u < team; ++u) {
          const Index here = counts[std::size_t(u) * std::size_t(n) + std::size_t(i)];
          counts[std::size_t(u) * std::size_t(n) + std::size_t(i)] = running;
          running += here;
        }
      }
      row_start[n] = running;
      next_j.resize(running);
    }
    for (long b = b0; b < b1; ++b)
      for (const auto& pr : found[std::size_t(b)]) next_j[mine[pr[0]]++] = pr[1];
#pragma omp barrier
#pragma omp for schedule(static)
    for (long i = 0; i < n; ++i) std::sort(next_j.begin() + row_start[i], next_j.begin() + row_start[i + 1]);
  }
  // Wall candidates per particle, in fixed blocks of particles joined in block order.
  constexpr long kRowsPerBlock = 256;
  const long blocks = (n + kRowsPerBlock - 1) / kRowsPerBlock;
  std::vector<std::vector<Index>> blockWalls(static_cast<std::size_t>(blocks));
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
  for (long b = 0; b < blocks; ++b) {
    auto& wallsNear = blockWalls[std::size_t(b)];
    for (long i = b * kRowsPerBlock; i < std::min(n, (b + 1) * kRowsPerBlock); ++i) {
      const std::size_t firstWall = wallsNear.size();
      for (std::size_t k = 0; k < walls.size(); ++k)
        if (walls.distanceTo(k, p.x[i]) < p.radius[i] + skin_) wallsNear.push_back(static_cast<Index>(k));
      wall_start[i + 1] = static_cast<Index>(wallsNear.size() - firstWall);
    }
  }
  for (long i = 0; i < n; ++i) wall_start[i + 1] += wall_start[i];
  j = std::move(next_j);
  shear.assign(row_start[n], Vector3d::Zero());
  wall_id.resize(wall_start[n]);
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
  for (long b = 0; b < blocks; ++b) {
    const long i0 = b * kRowsPerBlock, i1 = std::min(n, (b + 1) * kRowsPerBlock);
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
