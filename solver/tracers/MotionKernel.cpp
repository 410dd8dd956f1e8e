#include "tracers/MotionKernel.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <cmath>
#include <exception>
#include <limits>
#include <string>

#include <omp.h>

#include "core/Errors.hpp"
#include "geometry/WallClearance.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/FluctuationModel.hpp"
#include "tracers/BlockLanes.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/SingleSphereDrag.hpp"
#include "tracers/UnitVectors.hpp"

namespace rcfd {

// move() reads a cell's [reach, speed] floats as one 64-bit word, reach in the low half.
static_assert(std::endian::native == std::endian::little);

MotionKernel::MotionKernel(const TracerContext& ctx, const MotionSettings& settings)
    : settings_(settings), apparatus_(ctx.apparatus), grid_(ctx.grid), reference_(ctx, settings) {
  // The block loops index the 4-float step field with int32 (4 x cells < 2^31).
  if (grid_.cellCount() > std::int64_t(1) << 29) {
    throw RunError("grid of " + std::to_string(grid_.cellCount()) + " cells: the tracer kernel supports at most 2^29");
  }
  minSpacing_ = grid_.spacing.minCoeff();
  const auto& p = ctx.scene.particles;
  const auto& g = ctx.scene.gas;
  reynoldsPerSpeed_ = p.diameter / g.kinematic_viscosity;
  inverseStokesTime_ = 18.0 * g.density * g.kinematic_viscosity / (p.density * p.diameter * p.diameter);
  if (settings_.walls) {
    // The block path's first wall test: the per-point bound sd(p) >= sd(centre) - |p - centre| (signed
    // distances are 1-Lipschitz) against `reach`, sd(centre) less twice the band in which
    // firstIntersection() reports hits, so a move it accepts is one the exact test would not stop.
    const double band = 2.0 * apparatus_.boundaryTolerance();
    reach_ = cellWallClearance(apparatus_, grid_, band);
    halfSpaces_ = apparatus_.convexHalfSpaces();
    // Which half-spaces the block path's second wall test needs per cell: a cell near a z wall need not
    // test the outline's six planes, a cell at a V wall not the z walls. Moves of up to 1.5 cells (the
    // Courant limit's sub-steps, with room for the midpoint velocity) read their cell's mask; longer
    // ones test every plane.
    if (halfSpaces_.size() <= std::size_t(block::Context::kMaxHalfSpaces)) {
      nearReach_ = 1.5 * grid_.spacing.minCoeff();
      nearHalfSpaces_ = nearHalfSpaceMasks(halfSpaces_, grid_, band, nearReach_);
    }
    // Distance from each cell centre to the draft plates less the band: a move with
    // |p - centre| + |disp| below it cannot reach a plate (the block path's second wall test).
    const auto& holes = apparatus_.holes();
    if (!holes.empty()) {
      plateReach_.resize(std::size_t(grid_.cellCount()));
#pragma omp parallel for schedule(static) if (grid_.cellCount() > kParallelThreshold)
      for (std::int64_t c = 0; c < grid_.cellCount(); ++c) {
        const auto ijk = grid_.cellIjk(c);
        const Eigen::Vector3d centre = grid_.cellCenter(ijk[0], ijk[1], ijk[2]);
        double nearest = std::numeric_limits<double>::infinity();
        for (const auto& hole : holes) {
          Eigen::Vector2d lo = hole.front(), hi = hole.front();
          for (const auto& v : hole) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
          const Eigen::Vector2d q = centre.head<2>().cwiseMax(lo).cwiseMin(hi);  // nearest point of the plate
          nearest = std::min(nearest, (centre.head<2>() - q).norm());
        }
        plateReach_[std::size_t(c)] = float(std::max(0.0, nearest - band) * (1.0 - 1e-6));
      }
    }
  }
}

int MotionKernel::moveWithWalls(Eigen::Vector3d& p, const Eigen::Vector3d& disp, Eigen::Vector3d* velocity,
                                double restitution) const {
  return reference_.moveReflecting(p, disp, velocity, restitution);
}

void MotionKernel::prepare(TracerContext& ctx, const FrameSampler& sampler, bool fluctuate) {
  const std::int64_t cells = grid_.cellCount();
  const bool parallel = cells > kParallelThreshold;
  particleVelocity_ = &ctx.stepVelocity(false);
  gasVelocity_ = settings_.freeFlight ? &ctx.stepVelocity(true) : nullptr;
  if (cellData_.empty()) {
    cellData_.assign(2 * std::size_t(cells), 0.0f);
    if (settings_.walls) {
      for (std::int64_t c = 0; c < cells; ++c) cellData_[2 * std::size_t(c)] = reach_[std::size_t(c)];
    }
  }
  const FluctuationModel* model = fluctuate ? settings_.fluctuation : nullptr;
  if (!model && !hadSpeeds_) return;
  hadSpeeds_ = model != nullptr;
  // Eq. (10), once per cell instead of once per tracer: it depends on the cell only. Both models give 0
  // in a cell without tracers, where no tracer reads it either. Chunks of cells through the model's
  // vectorised speeds().
  const double dt = ctx.dt;
  const float* recA = sampler.frame().alpha_p.data();
  const float* recB = sampler.nextFrame() ? sampler.nextFrame()->alpha_p.data() : nullptr;
  const double blend = sampler.blend();
  constexpr std::int64_t kChunk = 2048;
#pragma omp parallel for schedule(static) if (parallel)
  for (std::int64_t c0 = 0; c0 < cells; c0 += kChunk) {
    const std::int64_t count = std::min(kChunk, cells - c0);
    float* out = cellData_.data() + 2 * c0 + 1;
    if (model) {
      model->speeds(count, ctx.tracerAlpha.data() + c0, recA + c0, recB ? recB + c0 : nullptr, blend, settings_.d0,
                    dt, settings_.uFlucMax, out, 2);
    } else {
      for (std::int64_t c = 0; c < count; ++c) out[2 * c] = 0.0f;
    }
  }
}


block::Context MotionKernel::blockContext(const TrilinearLocator& locator, double dt) const {
  using block::Context;
  Context bc;
  bc.field = particleVelocity_->floats();
  bc.gasField = settings_.freeFlight ? gasVelocity_->floats() : nullptr;
  bc.inverseStokesTime = inverseStokesTime_;
  bc.reynoldsPerSpeed = reynoldsPerSpeed_;
  for (int d = 0; d < 3; ++d) bc.gravity[d] = gravity_[d];
  bc.restitution = settings_.wallRestitution;
  static_assert(Context::kMaxSubsteps == kMaxSubsteps);
  for (int k = 1; k <= kMaxSubsteps; ++k) bc.substepLength[k] = dt / k;  // the reference's h = dt / nsub
  bc.cellData = cellData_.data();
  bc.plateReach = plateReach_.empty() ? nullptr : plateReach_.data();
  bc.q = locator.constants();
  bc.grid = block::GridConstants(bc.q);
  bc.corners.set(locator.offsets32());
  bc.corners.weighted = particleVelocity_->weighted();  // u_G's padded field has weight 1: read alike
  for (int d = 0; d < 3; ++d) {
    bc.origin[d] = grid_.origin[d], bc.inv[d] = 1.0 / grid_.spacing[d], bc.spacing[d] = grid_.spacing[d];
    bc.last[d] = grid_.shape[d] - 1;
  }
  bc.sy = grid_.shape[0], bc.sz = grid_.shape[0] * grid_.shape[1];
  bc.noWall = settings_.walls ? 0.0 : 1e300;
  bc.halfDiagonal = 0.5 * grid_.spacing.norm();
  bc.midpoint = settings_.midpoint;
  if (settings_.walls && halfSpaces_.size() <= std::size_t(Context::kMaxHalfSpaces)) {
    bc.halfSpaces = int(halfSpaces_.size());
    for (int j = 0; j < bc.halfSpaces; ++j) {
      const auto& hs = halfSpaces_[std::size_t(j)];
      bc.hx[j] = hs.n.x(), bc.hy[j] = hs.n.y(), bc.hz[j] = hs.n.z(), bc.hc[j] = hs.c;
    }
    bc.margin = 2.0 * apparatus_.boundaryTolerance();
    if (!nearHalfSpaces_.empty()) bc.nearHalfSpaces = nearHalfSpaces_.data(), bc.nearReach2 = nearReach_ * nearReach_;
  }
  bc.keepVelocity = settings_.freeFlight;
  return bc;
}

void MotionKernel::startBlock(const block::StepInputs& in, std::int64_t i0, int count, block::BlockStart& b) const {
  using block::kBlock;
  // The lanes' cells: those tracer_volume_fraction found for the step (read in place), or found here.
  b.cell = b.cellsFound;
  if (in.tracerCell) {
    b.cell = in.tracerCell + i0;
  } else {
    in.indexer->cellsOf(count, in.cloud.x + i0, in.cloud.y + i0, in.cloud.z + i0, b.cellsFound);
  }
  // `free` is read only where freeLanes > 0 (without free_flight, zeroing it was a memset per block).
  b.freeLanes = 0;
  if (settings_.freeFlight) {
    for (int k = 0; k < count; ++k) {
      b.free[k] = in.sampler->alphaP(b.cell[k]) < settings_.freeFlightAlpha;
      b.freeLanes += b.free[k];
    }
  }
  // A cell's reach and speed side by side: one 64-bit gather per lane for both.
  const float* cellData = cellData_.data();
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

namespace {
/// The lanes of a block in free flight (or not) copied out of the cloud into `ls`, with their velocity
/// (free flight's own) and, for the others, their u_fluc.
block::Lanes takeLanes(bool freeFlying, const block::Cloud& cloud, std::int64_t i0, int count,
                       const block::BlockStart& b, block::LaneStorage& ls) {
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
void putBack(const block::Lanes& lanes, const block::LaneStorage& ls, const block::Cloud& cloud, std::int64_t i0) {
  for (int j = 0; j < lanes.count; ++j) {
    const std::int64_t i = i0 + ls.lane[j];
    cloud.x[i] = lanes.x[j], cloud.y[i] = lanes.y[j], cloud.z[i] = lanes.z[j];
    cloud.vx[i] = lanes.ux[j], cloud.vy[i] = lanes.uy[j], cloud.vz[i] = lanes.uz[j];
  }
}
}  // namespace

void MotionKernel::moveBlock(const block::StepInputs& in, std::int64_t i0, int count, block::BlockStart& b,
                             block::ThreadLanes& thread, MotionStatistics& st) const {
  using namespace block;
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
  const bool keep = settings_.freeFlight;
  Lanes L{cloud.x + i0, cloud.y + i0, cloud.z + i0, b.ax, b.ay, b.az, keep ? cloud.vx + i0 : sux,
          keep ? cloud.vy + i0 : suy, keep ? cloud.vz + i0 : suz, h, left, count, b.cell, b.reach};
  if (b.freeLanes > 0) L = takeLanes(false, cloud, i0, count, b, compact);
  // Eq. (9): u_P^rec + u_fluc at the start, which sets the sub-steps.
  sampleParticleVelocity(bc, L, thread.stencils);
  auto countSubsteps = [&](Lanes& lanes) {
    return substepsOfBlock(lanes.ux, lanes.uy, lanes.uz, lanes.count, in.dt, in.inverseCellLimit, bc.substepLength,
                           double(kMaxSubsteps), lanes.h, lanes.left, st.substeps, st.substepCapped);
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

void MotionKernel::move(TracerContext& ctx, const std::function<void()>& beside) {
  using namespace block;
  stats_ = {};
  if (!settings_.transport) {
    if (beside) beside();
    return;
  }
  if (!settings_.vectorised) {
    if (beside) beside();
    reference_.move(ctx, stats_);
    return;
  }
  TracerCloud& cloud = ctx.cloud;
  const FrameSampler sampler = ctx.sampler();
  const double dt = ctx.dt;
  const bool haveTracerAlpha = !ctx.tracerAlpha.empty() && !ctx.tracerCell.empty();
  prepare(ctx, sampler, settings_.fluctuation && haveTracerAlpha);
  const CounterRngPrefix rngPrefix(ctx.seed, RngPurpose::Fluctuation, std::uint64_t(ctx.step));
  const std::int64_t n = std::int64_t(cloud.size());
  const CellIndexer indexer(grid_);
  std::int32_t* const nextCells = ctx.nextTracerCell.size() == cloud.size() ? ctx.nextTracerCell.data() : nullptr;
  const Cloud arrays{cloud.x.data(), cloud.y.data(), cloud.z.data(), cloud.vx.data(), cloud.vy.data(), cloud.vz.data()};
  Context bc = blockContext(sampler.locator(), dt);
  bc.cloudX = arrays.x, bc.cloudY = arrays.y, bc.cloudZ = arrays.z;
  bc.cloudVx = arrays.vx, bc.cloudVy = arrays.vy, bc.cloudVz = arrays.vz;
  bc.nextCells = nextCells, bc.cellIndexer = &indexer;
  StepInputs in;
  in.cloud = arrays;
  in.context = &bc;
  in.ids = cloud.id.data();
  in.sampler = &sampler;
  in.indexer = &indexer;
  in.rngPrefix = &rngPrefix;
  in.tracerCell = haveTracerAlpha ? ctx.tracerCell.data() : nullptr;
  in.fluctuate = settings_.fluctuation && haveTracerAlpha;
  if (ctx.streamVelocity[0].size() == cloud.size()) {
    in.streamX = ctx.streamVelocity[0].data(), in.streamY = ctx.streamVelocity[1].data();
    in.streamZ = ctx.streamVelocity[2].data();
  }
  in.dt = dt;
  // Sub-steps so that none moves farther than max_courant cells.
  in.inverseCellLimit = 1.0 / (settings_.maxCourant * minSpacing_);

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
  // The thread's deferred lanes, carried from chunk to chunk so that their rounds run full.
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
  if (nextCells) ctx.nextTracerCellStep = ctx.step + 1;
  stats_.substeps = substeps;
  stats_.wallHits = wallHits;
  stats_.freeFlight = freeFlight;
  stats_.substepCapped = capped;
  stats_.scalarPath = scalarPath;
  stats_.exactWallTests = exactWallTests;
  stats_.blocksInPlace = blocksInPlace;
}

}  // namespace rcfd
