// The motion kernel's block path: lanes of a block of tracers sub-stepped together in loops the
// compiler vectorises, with ReferenceMotion's arithmetic, so both give the same trajectories. Compiled
// once per kernel variant (BlockPath.hpp); the strategies are explained in MotionKernel.hpp.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <exception>

#if defined(__AVX2__)
#include <immintrin.h>
#endif
#include <omp.h>

#include "tracers/BlockPath.hpp"
#include "tracers/ReferenceMotion.hpp"
#include "tracers/SingleSphereDrag.hpp"
#include "tracers/TracerContext.hpp"
#include "tracers/UnitVectors.hpp"

namespace rcfd::block::RCFD_ISA_NAMESPACE {
namespace {

// The sub-step passes. Each takes the step's constants `bc` and adds what it did to `st`.
/// One sub-step of lanes along u_P^rec + u_fluc (sampled at the start already when `sampled`).
void subStep(Lanes& lanes, BlockStencils& stencils, bool sampled, const Context& bc, MotionStatistics& st);
/// One sub-step of free-flying lanes: drag toward u_G^rec and gravity, then the move.
void freeFlightSubStep(Lanes& lanes, BlockStencils& stencils, const Context& bc, MotionStatistics& st);
/// The moves of a sub-step: the vectorised wall tests, then the exact segment test (and, for free
/// flight, the velocity's reflection) for the moves they do not clear.
void moveLanes(Lanes& lanes, const Context& bc, MotionStatistics& st, bool freeFlying);
/// The sub-steps after the first of lanes: passes on the lanes that still have some, compacted.
void advanceLanes(Lanes& lanes, std::int32_t maxLeft, BlockStencils& stencils, bool freeFlying, const Context& bc,
                  MotionStatistics& st);
/// The sub-steps after the first of the lanes of a block in place, when most of its lanes have some
/// (in the spout every lane does): passes over the whole block, in which the lanes without sub-steps
/// left stand still (a zero sub-step) and keep their velocity. Spares the copies of defer().
void advanceInPlace(Lanes& lanes, BlockStencils& stencils, const Context& bc, MotionStatistics& st);
/// Adds the lanes with sub-steps left (lane k is tracer i0 + k, or i0 + laneOf[k]) to `deferred`,
/// finishing its lanes whenever it is full.
void defer(const Lanes& lanes, std::int64_t i0, const std::int32_t* laneOf, DeferredLanes& deferred, bool freeFlying,
           BlockStencils& stencils, const Context& bc, MotionStatistics& st);
/// The remaining sub-steps of deferred lanes, then their positions (and velocities) into the cloud.
void finishDeferred(DeferredLanes& deferred, bool freeFlying, BlockStencils& stencils, const Context& bc,
                    MotionStatistics& st);

void subStep(Lanes& L, BlockStencils& s, bool sampled, const Context& bc,
                           MotionStatistics& st) {
  const int m = L.count;
  if (!sampled) sampleParticleVelocity(bc, L, s);  // Eq. (9) at the sub-step's start
  if (bc.midpoint) {  // the midpoint rule (see moveOne), in grid coordinates
    alignas(64) float mx[kBlock], my[kBlock], mz[kBlock];
    const float fix = bc.grid.fix, fiy = bc.grid.fiy, fiz = bc.grid.fiz;
#pragma omp simd
    for (int k = 0; k < m; ++k) {
      const float half = float(0.5 * L.h[k]);
      mx[k] = s.gx[k] + half * (s.ux[k] * fix), my[k] = s.gy[k] + half * (s.uy[k] * fiy), mz[k] = s.gz[k] + half * (s.uz[k] * fiz);
    }
    locateGridBlock(bc.grid, m, mx, my, mz, s);
    sampleBlockFloat(bc.field, bc.corners, s, m, L.ax, L.ay, L.az, s.ux, s.uy, s.uz, L.ux, L.uy, L.uz);
  }
  moveLanes(L, bc, st, false);
}

void moveLanes(Lanes& L, const Context& bc, MotionStatistics& st, bool freeFlying) {
  const int m = L.count;
  // Plain local pointers: the vectoriser does not look through the view's members.
  double* const x = L.x;
  double* const y = L.y;
  double* const z = L.z;
  double* const ux = L.ux;
  double* const uy = L.uy;
  double* const uz = L.uz;
  const double* const h = L.h;
  // Walls, first test: |p - c| + |disp| < reach(c) for the centre c of p's cell keeps the whole move
  // inside (signed distances are 1-Lipschitz).
  alignas(64) std::int64_t fast[kBlock];
  alignas(64) double ex[kBlock], ey[kBlock], ez[kBlock];  // end points
  alignas(64) double off[kBlock], length2[kBlock];  // |p - c|, |disp|^2
  alignas(64) std::int32_t cell[kBlock];
  const float* cellData = bc.cellData;
  const double noWall = bc.noWall;
  std::int64_t pending = 0;
  const std::int32_t* startCell = L.cell;
  const float* startReach = L.reach;
  const double halfDiagonal = bc.halfDiagonal;
#pragma omp simd
  for (int k = 0; k < m; ++k) {
    const double dx = h[k] * ux[k], dy = h[k] * uy[k], dz = h[k] * uz[k];
    ex[k] = x[k] + dx, ey[k] = y[k] + dy, ez[k] = z[k] + dz;
    length2[k] = dx * dx + dy * dy + dz * dz;
  }
  if (startCell) {
    // The lanes' cells are known (the step's first pass): the bound with |p - c| <= half a diagonal
    // spares locating every start point. (A separate loop: a branch inside stops the vectoriser.)
#pragma omp simd reduction(+ : pending)
    for (int k = 0; k < m; ++k) {
      off[k] = halfDiagonal;
      cell[k] = startCell[k];
      // |disp| < reach - off, squared (no square root where most lanes are decided)
      const double room = double(startReach[k]) + noWall - off[k];
      fast[k] = std::int64_t(room > 0.0) & std::int64_t(length2[k] < room * room);
      pending += 1 - fast[k];
    }
  } else {
    for (int k = 0; k < m; ++k) fast[k] = 0;
  }
  // The sharper per-point bound where the cells are not known, and near draft plates, whose test below
  // takes the distance from the centre.
  if (!startCell || (pending > 0 && bc.plateReach)) {
    pending = 0;
#pragma omp simd reduction(+ : pending)
    for (int k = 0; k < m; ++k) {
      int ci[3];
      double off2 = 0.0;
      const double pk[3] = {x[k], y[k], z[k]};
      for (int d = 0; d < 3; ++d) {
        const double t = (pk[d] - bc.origin[d]) * bc.inv[d];
        const int i = int(t > 0.0 ? t : 0.0);
        ci[d] = i < bc.last[d] ? i : bc.last[d];
        const double e = pk[d] - (bc.origin[d] + (double(ci[d]) + 0.5) * bc.spacing[d]);
        off2 += e * e;
      }
      off[k] = std::sqrt(off2);
      cell[k] = ci[0] + ci[1] * bc.sy + ci[2] * bc.sz;
      const double reach = double(cellData[2 * cell[k]]) + noWall;
      fast[k] = fast[k] | std::int64_t(off[k] + std::sqrt(length2[k]) < reach);
      pending += 1 - fast[k];
    }
  }
  // Second test, for moves near a wall: the end at least `margin` inside every half-space of the
  // outline and the z walls, and the whole move farther than the hit band from the draft plates. Then
  // firstIntersection() reports no hit: from a start clear of a wall's band both ends are clear, and
  // from a start inside the band the move goes inwards, which is not a hit either.
  if (pending > 0 && bc.halfSpaces > 0) {
    const double margin = bc.margin;
    const float* plateReach = bc.plateReach;
    alignas(64) std::int64_t inside[kBlock];
    if (plateReach) {
#pragma omp simd
      for (int k = 0; k < m; ++k) inside[k] = off[k] + std::sqrt(length2[k]) < double(plateReach[cell[k]]);
    } else {
#pragma omp simd
      for (int k = 0; k < m; ++k) inside[k] = 1;
    }
    // Only the planes some pending lane's cell is near (a lane moving farther than nearReach needs all):
    // a plane left out would have passed (nearHalfSpaceMasks()), so the decisions are those of testing all.
    const std::uint32_t all = (std::uint32_t(1) << bc.halfSpaces) - 1;
    std::uint32_t planes = all;
    if (const std::uint32_t* near = bc.nearHalfSpaces) {
      const double nearReach2 = bc.nearReach2;
      planes = 0;
#pragma omp simd reduction(| : planes)
      for (int k = 0; k < m; ++k) {  // loads unconditional, selects after: a gather and blends
        const std::uint32_t cellPlanes = near[cell[k]];
        const std::uint32_t lane = length2[k] <= nearReach2 ? cellPlanes : all;
        planes |= fast[k] != 0 ? 0u : lane;
      }
    }
    for (; planes != 0; planes &= planes - 1) {
      const int j = std::countr_zero(planes);
      const double nx = bc.hx[j], ny = bc.hy[j], nz = bc.hz[j], c = bc.hc[j];
#pragma omp simd
      for (int k = 0; k < m; ++k) inside[k] &= std::int64_t(nx * ex[k] + ny * ey[k] + nz * ez[k] - c >= margin);
    }
    pending = 0;
#pragma omp simd reduction(+ : pending)
    for (int k = 0; k < m; ++k) {
      fast[k] |= inside[k];
      pending += 1 - fast[k];
    }
  }
  // `pending` lanes are left for the exact test.
  if (pending == 0) {  // most blocks: every move accepted
#pragma omp simd
    for (int k = 0; k < m; ++k) x[k] = ex[k], y[k] = ey[k], z[k] = ez[k];
    return;
  }
  int k0 = 0;
#if defined(__AVX2__) && !defined(__AVX512F__)
  // Blends and plain stores: GCC turns this loop, even written as selects, into AVX2 masked stores
  // (vmaskmovpd), which are slow on AMD cores.
  for (; k0 + 4 <= m; k0 += 4) {
    const __m256d move = _mm256_castsi256_pd(_mm256_cmpgt_epi64(
        _mm256_load_si256(reinterpret_cast<const __m256i*>(fast + k0)), _mm256_setzero_si256()));
    _mm256_storeu_pd(x + k0, _mm256_blendv_pd(_mm256_loadu_pd(x + k0), _mm256_load_pd(ex + k0), move));
    _mm256_storeu_pd(y + k0, _mm256_blendv_pd(_mm256_loadu_pd(y + k0), _mm256_load_pd(ey + k0), move));
    _mm256_storeu_pd(z + k0, _mm256_blendv_pd(_mm256_loadu_pd(z + k0), _mm256_load_pd(ez + k0), move));
  }
#endif
#pragma omp simd
  for (int k = k0; k < m; ++k) {
    if (fast[k]) x[k] = ex[k], y[k] = ey[k], z[k] = ez[k];  // masked stores (all lanes with AVX-512)
  }
  // The rest meet a wall or pass close to one: the exact segment test and mirror reflection, which
  // for a free-flying tracer also reflects its velocity with the restitution coefficient.
  for (int k = 0; k < m; ++k) {
    if (fast[k] || h[k] == 0.0) continue;  // h = 0: a lane standing still in advanceInPlace()
    Eigen::Vector3d p(x[k], y[k], z[k]);
    Eigen::Vector3d u(ux[k], uy[k], uz[k]);
    st.wallHits += bc.exact->moveReflecting(p, h[k] * u, freeFlying ? &u : nullptr, bc.restitution);
    ++st.exactWallTests;
    x[k] = p.x(), y[k] = p.y(), z[k] = p.z();
    ux[k] = u.x(), uy[k] = u.y(), uz[k] = u.z();
  }
}


void freeFlightSubStep(Lanes& F, BlockStencils& s, const Context& bc,
                                     MotionStatistics& st) {
  const int m = F.count;
  // u_G^rec at the sub-step's start (no fluctuation in free flight).
  alignas(64) static constexpr double kZero[kBlock] = {};
  alignas(64) double gx[kBlock], gy[kBlock], gz[kBlock];
  locateBlock(bc.q, m, F.x, F.y, F.z, s);
  sampleBlock(bc.gasField, bc.corners, s, m, kZero, kZero, kZero, gx, gy, gz);
  // Implicit drag relaxation toward u_G^rec plus gravity, stable for any h / tau (as moveOne).
  double* const vx = F.ux;
  double* const vy = F.uy;
  double* const vz = F.uz;
  const double* const h = F.h;
  const double inverseStokesTime = bc.inverseStokesTime, rePerSpeed = bc.reynoldsPerSpeed;
  const double g0 = bc.gravity[0], g1 = bc.gravity[1], g2 = bc.gravity[2];
#pragma omp simd
  for (int k = 0; k < m; ++k) {
    const double dx = gx[k] - vx[k], dy = gy[k] - vy[k], dz = gz[k] - vz[k];
    const double re = std::sqrt(dx * dx + dy * dy + dz * dz) * rePerSpeed;
    const double inverseTau = singleSphereDragFactor(re) * inverseStokesTime;  // one division per lane:
    const double relaxation = 1.0 / (1.0 + h[k] * inverseTau);                 // the scalar path's order
    vx[k] = (vx[k] + h[k] * (gx[k] * inverseTau + g0)) * relaxation;
    vy[k] = (vy[k] + h[k] * (gy[k] * inverseTau + g1)) * relaxation;
    vz[k] = (vz[k] + h[k] * (gz[k] * inverseTau + g2)) * relaxation;
  }
  moveLanes(F, bc, st, true);
}

void advanceLanes(Lanes& L, std::int32_t maxLeft, BlockStencils& s, bool freeFlying,
                                const Context& bc, MotionStatistics& st) {
  auto subStepRound = [&](Lanes& lanes) {
    if (freeFlying) {
      freeFlightSubStep(lanes, s, bc, st);
    } else {
      subStep(lanes, s, false, bc, st);
    }
  };
  for (std::int32_t n = 1; n <= maxLeft; ++n) {
    LaneStorage rs;
    const int r = lanesWithSubstepsLeft(L, rs.lane);
    if (r == L.count) {
      // Every lane takes this pass (always the first pass of deferred lanes): in place, no copies.
      for (int k = 0; k < r; ++k) --L.left[k];
      Lanes all = L;
      all.cell = nullptr, all.reach = nullptr;  // later passes: the cells are not known
      subStepRound(all);
      continue;
    }
    for (int j = 0; j < r; ++j) {
      rs.copyLane(L, rs.lane[j], j, freeFlying);
      --L.left[rs.lane[j]];
    }
    Lanes R = rs.view(r);
    subStepRound(R);
    const bool velocity = freeFlying || bc.keepVelocity;  // else no one reads it
    for (int j = 0; j < r; ++j) {
      const int k = rs.lane[j];
      L.x[k] = R.x[j], L.y[k] = R.y[j], L.z[k] = R.z[j];
      if (velocity) L.ux[k] = R.ux[j], L.uy[k] = R.uy[j], L.uz[k] = R.uz[j];
    }
  }
}

void advanceInPlace(Lanes& L, BlockStencils& s, const Context& bc,
                                  MotionStatistics& st) {
  const int m = L.count;
  alignas(64) double h[kBlock], ux[kBlock], uy[kBlock], uz[kBlock];
  alignas(64) std::int32_t on[kBlock];
  Lanes all = L;
  all.h = h, all.ux = ux, all.uy = uy, all.uz = uz;  // a pass reads no `left`
  all.cell = nullptr, all.reach = nullptr;  // the cells are not known after the first sub-step
  for (;;) {
    std::int32_t active = 0;
#pragma omp simd reduction(+ : active)
    for (int k = 0; k < m; ++k) {
      on[k] = L.left[k] > 0 ? 1 : 0;
      h[k] = on[k] != 0 ? L.h[k] : 0.0;  // x + 0 u = x: a lane without sub-steps left stands still
      L.left[k] -= on[k];
      active += on[k];
    }
    if (active == 0) return;
    subStep(all, s, false, bc, st);
#pragma omp simd
    for (int k = 0; k < m; ++k) {
      L.ux[k] = on[k] != 0 ? ux[k] : L.ux[k];
      L.uy[k] = on[k] != 0 ? uy[k] : L.uy[k];
      L.uz[k] = on[k] != 0 ? uz[k] : L.uz[k];
    }
  }
}

void defer(const Lanes& L, std::int64_t i0, const std::int32_t* laneOf, DeferredLanes& d,
                         bool freeFlying, BlockStencils& s, const Context& bc,
                         MotionStatistics& st) {
  std::int32_t lanes[kBlock];
  const int r = lanesWithSubstepsLeft(L, lanes);
  for (int q = 0; q < r; ++q) {
    const int k = lanes[q];
    if (d.count == kBlock) finishDeferred(d, freeFlying, s, bc, st);
    const int j = d.count++;
    d.s.copyLane(L, k, j, freeFlying);
    d.tracer[j] = i0 + (laneOf ? laneOf[k] : k);
  }
}

void finishDeferred(DeferredLanes& d, bool freeFlying, BlockStencils& s,
                                  const Context& bc, MotionStatistics& st) {
  if (d.count == 0) return;
  Lanes D = d.s.view(d.count);
  std::int32_t maxLeft = 0;
  for (int j = 0; j < d.count; ++j) maxLeft = std::max(maxLeft, d.s.left[j]);
  advanceLanes(D, maxLeft, s, freeFlying, bc, st);
  for (int j = 0; j < d.count; ++j) {
    const std::int64_t i = d.tracer[j];
    bc.cloudX[i] = D.x[j], bc.cloudY[i] = D.y[j], bc.cloudZ[i] = D.z[j];
    if (bc.keepVelocity) bc.cloudVx[i] = D.ux[j], bc.cloudVy[i] = D.uy[j], bc.cloudVz[i] = D.uz[j];
  }
  if (bc.nextCells) {  // over the cells its chunk's end found for the positions after the first sub-step
    alignas(64) std::int32_t cells[kBlock];
    bc.cellIndexer->cellsOf(d.count, D.x, D.y, D.z, cells);
    for (int j = 0; j < d.count; ++j) bc.nextCells[d.tracer[j]] = cells[j];
  }
  d.count = 0;
}

/// A block's start: its lanes' cells, which are in free flight, their cells' reach and u_fluc.
void startBlock(const StepInputs& in, std::int64_t i0, int count, BlockStart& b) {
  // The lanes' cells: those tracer_volume_fraction found for the step (read in place), or found here.
  b.cell = b.cellsFound;
  if (in.tracerCell) {
    b.cell = in.tracerCell + i0;
  } else {
    in.indexer->cellsOf(count, in.cloud.x + i0, in.cloud.y + i0, in.cloud.z + i0, b.cellsFound);
  }
  // `free` is read only where freeLanes > 0 (without free_flight, zeroing it was a memset per block).
  b.freeLanes = 0;
  if (in.freeFlight) {
    for (int k = 0; k < count; ++k) {
      b.free[k] = in.sampler->alphaP(b.cell[k]) < in.freeFlightAlpha;
      b.freeLanes += b.free[k];
    }
  }
  // A cell's reach and speed side by side: one 64-bit gather per lane for both.
  const float* cellData = in.context->cellData;
  alignas(64) float speed[kBlock];
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    std::uint64_t pair;
    std::memcpy(&pair, cellData + 2 * b.cell[k], sizeof pair);
    b.reach[k] = std::bit_cast<float>(std::uint32_t(pair));
    speed[k] = std::bit_cast<float>(std::uint32_t(pair >> 32));
  }
  if (b.freeLanes > 0) {  // none in free flight (a select: AVX2 has no vector int64-to-double conversion)
#pragma omp simd
    for (int k = 0; k < count; ++k) speed[k] = b.free[k] != 0 ? 0.0f : speed[k];
  }
  // Eq. (10): u_fluc = |u_fluc| n_rand, n_rand from the tracer's counter-based stream.
  if (in.fluctuate) {
#pragma omp simd
    for (int k = 0; k < count; ++k) {
      float nx, ny, nz;
      counterUnitVectorFloat(*in.rngPrefix, std::uint64_t(in.ids[i0 + k]), nx, ny, nz);  // the tracer's own stream
      b.ax[k] = speed[k] * nx, b.ay[k] = speed[k] * ny, b.az[k] = speed[k] * nz;
    }
  } else {
    for (int k = 0; k < count; ++k) b.ax[k] = b.ay[k] = b.az[k] = 0.0f;
  }
  // The tracer's stream velocity relative to u_P^rec (velocity_streams), held over the step as u_fluc is.
  if (in.streamX) {
#pragma omp simd
    for (int k = 0; k < count; ++k) {
      b.ax[k] += in.streamX[i0 + k], b.ay[k] += in.streamY[i0 + k], b.az[k] += in.streamZ[i0 + k];
    }
  }
}

/// The lanes of a block in free flight (or not) copied out of the cloud into `ls`, with their velocity
/// (free flight's own) and, for the others, their u_fluc.
Lanes takeLanes(bool freeFlying, const Cloud& cloud, std::int64_t i0, int count,
                       const BlockStart& b, LaneStorage& ls) {
  int j = 0;
  for (int k = 0; k < count; ++k) {
    if ((b.free[k] != 0) != freeFlying) continue;
    const std::int64_t i = i0 + k;
    ls.x[j] = cloud.x[i], ls.y[j] = cloud.y[i], ls.z[j] = cloud.z[i];
    ls.ux[j] = cloud.vx[i], ls.uy[j] = cloud.vy[i], ls.uz[j] = cloud.vz[i];
    ls.ax[j] = freeFlying ? 0.0f : b.ax[k], ls.ay[j] = freeFlying ? 0.0f : b.ay[k], ls.az[j] = freeFlying ? 0.0f : b.az[k];
    ls.cell[j] = b.cell[k], ls.reach[j] = b.reach[k];
    ls.lane[j++] = k;
  }
  return ls.view(j, true);
}

/// takeLanes()'s lanes back into the cloud.
void putBack(const Lanes& lanes, const LaneStorage& ls, const Cloud& cloud, std::int64_t i0) {
  for (int j = 0; j < lanes.count; ++j) {
    const std::int64_t i = i0 + ls.lane[j];
    cloud.x[i] = lanes.x[j], cloud.y[i] = lanes.y[j], cloud.z[i] = lanes.z[j];
    cloud.vx[i] = lanes.ux[j], cloud.vy[i] = lanes.uy[j], cloud.vz[i] = lanes.uz[j];
  }
}

/// A block's move: its first sub-step, the later ones in place or deferred, and its free flight.
void moveBlock(const StepInputs& in, std::int64_t i0, int count, BlockStart& b,
                             ThreadLanes& thread, MotionStatistics& st) {
  const Context& bc = *in.context;
  const Cloud& cloud = in.cloud;
  // The lanes that follow u_P^rec: all of them, in place in the cloud's arrays (the velocity arrays hold
  // u as it is computed), unless some are in free flight.
  alignas(64) double h[kBlock];
  alignas(64) std::int32_t left[kBlock];
  LaneStorage compact;
  // Velocities are kept in the cloud only for free flight, the one reader; otherwise they stay in the
  // block (saves writing 24 bytes per tracer-step).
  alignas(64) double sux[kBlock], suy[kBlock], suz[kBlock];
  const bool keep = in.freeFlight;
  Lanes L{cloud.x + i0, cloud.y + i0, cloud.z + i0, b.ax, b.ay, b.az, keep ? cloud.vx + i0 : sux,
          keep ? cloud.vy + i0 : suy, keep ? cloud.vz + i0 : suz, h, left, count, b.cell, b.reach};
  if (b.freeLanes > 0) L = takeLanes(false, cloud, i0, count, b, compact);
  // Eq. (9): u_P^rec + u_fluc at the start, which sets the sub-steps.
  sampleParticleVelocity(bc, L, thread.stencils);
  auto countSubsteps = [&](Lanes& lanes) {
    return substepsOfBlock(lanes.ux, lanes.uy, lanes.uz, lanes.count, in.dt, in.inverseCellLimit, bc.substepLength,
                           double(Context::kMaxSubsteps), lanes.h, lanes.left, st.substeps, st.substepCapped);
  };
  const bool more = countSubsteps(L) > 0;
  subStep(L, thread.stencils, true, bc, st);
  // The later sub-steps: in place when most lanes take them, else deferred.
  const bool inPlace = more && countLanesWithSubstepsLeft(L) >= kInPlaceLanes;
  if (inPlace) advanceInPlace(L, thread.stencils, bc, st), ++st.blocksInPlace;
  // Copied back before deferring: deferring may finish lanes, whose results must not be overwritten.
  if (b.freeLanes > 0) putBack(L, compact, cloud, i0);
  if (more && !inPlace) {
    defer(L, i0, b.freeLanes > 0 ? compact.lane : nullptr, thread.deferred, false, thread.stencils, bc, st);
  }
  if (b.freeLanes > 0) {
    // Free flight: the tracers' own velocities, sub-stepped by them.
    LaneStorage fs;
    Lanes F = takeLanes(true, cloud, i0, count, b, fs);
    st.freeFlight += F.count;
    const bool moreFree = countSubsteps(F) > 0;
    freeFlightSubStep(F, thread.stencils, bc, st);
    putBack(F, fs, cloud, i0);
    if (moreFree) defer(F, i0, fs.lane, thread.deferredFree, true, thread.stencils, bc, st);
  }
}

}  // namespace

void moveTracers(const StepInputs& in, const std::function<void()>& beside, MotionStatistics& stats) {
  const Context& bc = *in.context;
  const Cloud& arrays = in.cloud;
  const CellIndexer& indexer = *in.indexer;
  std::int32_t* const nextCells = bc.nextCells;
  const std::int64_t n = in.tracers;
  std::int64_t substeps = 0, wallHits = 0, freeFlight = 0, capped = 0, scalarPath = 0, exactWallTests = 0;
  std::int64_t blocksInPlace = 0;
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
  constexpr std::int64_t kChunk = 16;  // blocks
  const std::int64_t chunks = (blocks + kChunk - 1) / kChunk;
  // `beside` on the team's last thread, which then takes what chunks are left (an exception is carried
  // out of the parallel region, which it must not leave).
  std::exception_ptr besideFailure;
#pragma omp parallel if (n > kParallelThreshold) \
    reduction(+ : substeps, wallHits, freeFlight, capped, scalarPath, exactWallTests, blocksInPlace)
  {
  if (beside && omp_get_thread_num() == omp_get_num_threads() - 1) {
    try {
      beside();
    } catch (...) {
      besideFailure = std::current_exception();
    }
  }
  // Defined in the region, so that it adds to the thread's copies of the reduction's counters.
  auto addStatistics = [&](const MotionStatistics& st) {
    substeps += st.substeps, wallHits += st.wallHits, freeFlight += st.freeFlight, capped += st.substepCapped;
    scalarPath += st.scalarPath, exactWallTests += st.exactWallTests, blocksInPlace += st.blocksInPlace;
  };
  // The thread's deferred lanes, carried from chunk to chunk so that their passes run full.
  ThreadLanes thread;
#pragma omp for schedule(dynamic, 1) nowait
  for (std::int64_t chunk = 0; chunk < chunks; ++chunk) {
    MotionStatistics st;
    for (std::int64_t b = chunk * kChunk; b < std::min(blocks, (chunk + 1) * kChunk); ++b) {
      const std::int64_t i0 = b * kBlock;
      const int count = int(std::min<std::int64_t>(kBlock, n - i0));
      BlockStart start;
      startBlock(in, i0, count, start);
      moveBlock(in, i0, count, start, thread, st);
    }
    if (nextCells) {  // the chunk's new positions are still in cache: their cells, for the next step
      // (deferred lanes are between sub-steps: finishDeferred() writes their cells when it moves them)
      const std::int64_t first = chunk * kChunk * kBlock, last = std::min(n, (chunk + 1) * kChunk * kBlock);
      indexer.cellsOf(int(last - first), arrays.x + first, arrays.y + first, arrays.z + first, nextCells + first);
    }
    addStatistics(st);
  }
  MotionStatistics st;
  finishDeferred(thread.deferred, false, thread.stencils, bc, st);
  finishDeferred(thread.deferredFree, true, thread.stencils, bc, st);
  addStatistics(st);
  }
  if (besideFailure) std::rethrow_exception(besideFailure);
  stats.substeps += substeps;
  stats.wallHits += wallHits;
  stats.freeFlight += freeFlight;
  stats.substepCapped += capped;
  stats.scalarPath += scalarPath;
  stats.exactWallTests += exactWallTests;
  stats.blocksInPlace += blocksInPlace;
}

}  // namespace rcfd::block::RCFD_ISA_NAMESPACE
