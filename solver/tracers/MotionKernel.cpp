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
    : settings_(settings), apparatus_(ctx.apparatus), grid_(ctx.grid) {
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
    // A point of cell c lies at most half a diagonal from its centre, so its wall distance is at least
    // sd(centre) - halfDiagonal: a move shorter than that cannot reach a wall (the fast path).
    // The block path uses the sharper per-point bound sd(p) >= sd(centre) - |p - centre| (signed
    // distances are 1-Lipschitz) against `reach`: sd(centre) less twice the band in which
    // firstIntersection() reports hits, so a move it accepts is one the exact test would not stop.
    const double halfDiagonal = 0.5 * grid_.spacing.norm();
    const double band = 2.0 * apparatus_.boundaryTolerance();
    clearance_ = cellWallClearance(apparatus_, grid_, halfDiagonal);
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

int MotionKernel::moveWithWalls(Eigen::Vector3d& p, Eigen::Vector3d disp, Eigen::Vector3d* velocity,
                                double restitution, double clearance) const {
  if (!settings_.walls) {
    p += disp;
    return 0;
  }
  int bounces = 0;
  for (; bounces <= kMaxBounces; ++bounces) {
    const double length = disp.norm();
    if (!(length > 0.0)) return bounces;
    if (!(bounces == 0 && clearance >= 0.0)) clearance = double(clearance_[std::size_t(grid_.flatIndexOf(p))]);
    if (clearance > length) {
      p += disp;
      return bounces;
    }
    const Eigen::Vector3d end = p + disp;
    const auto hit = apparatus_.firstIntersection(p, end);
    if (!hit) {
      p = end;
      return bounces;
    }
    // Mirror the rest of the displacement about the wall plane and continue from the hit point.
    const Eigen::Vector3d& n = hit->normal;
    Eigen::Vector3d rest = (1.0 - hit->t) * disp;
    rest -= 2.0 * rest.dot(n) * n;
    p = hit->point;
    disp = rest;
    if (velocity) {
      const double vn = velocity->dot(n);
      if (vn < 0.0) *velocity -= (1.0 + restitution) * vn * n;
    }
  }
  return bounces;  // gave up after kMaxBounces: p is the last point known to be inside
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


void MotionKernel::move(TracerContext& ctx, const std::function<void()>& beside) {
  using namespace block;
  stats_ = {};
  if (!settings_.transport) {
    if (beside) beside();
    return;
  }
  TracerCloud& cloud = ctx.cloud;
  const FrameSampler sampler = ctx.sampler();
  const TrilinearLocator& locator = sampler.locator();
  const double dt = ctx.dt;
  const bool haveTracerAlpha = !ctx.tracerAlpha.empty() && !ctx.tracerCell.empty();
  const bool fluctuate = settings_.fluctuation && haveTracerAlpha;
  prepare(ctx, sampler, fluctuate);
  const CounterRngPrefix rngPrefix(ctx.seed, RngPurpose::Fluctuation, std::uint64_t(ctx.step));
  const std::int64_t n = std::int64_t(cloud.size());
  std::int64_t substeps = 0, wallHits = 0, freeFlight = 0, capped = 0, scalarPath = 0, exactWallTests = 0;
  std::int64_t blocksInPlace = 0;
  // Sub-steps so that no sub-step moves farther than max_courant cells; a non-finite or enormous
  // displacement gets kMaxSubsteps (the exact wall tests still keep the tracer inside).
  const double inverseCellLimit = 1.0 / (settings_.maxCourant * minSpacing_);
  auto substepsFor = [inverseCellLimit](double distance, std::int64_t& cappedCount) -> int {
    const double courant = distance * inverseCellLimit;
    if (!(courant <= double(kMaxSubsteps))) {
      ++cappedCount;
      return kMaxSubsteps;
    }
    return std::max(1, int(std::ceil(courant)));
  };
  const bool walls = settings_.walls;
  const bool midpoint = settings_.midpoint;

  Context bc;
  bc.field = particleVelocity_->floats();
  bc.gasField = settings_.freeFlight ? gasVelocity_->floats() : nullptr;
  bc.inverseStokesTime = inverseStokesTime_;
  bc.reynoldsPerSpeed = reynoldsPerSpeed_;
  for (int d = 0; d < 3; ++d) bc.gravity[d] = gravity_[d];
  bc.restitution = settings_.wallRestitution;
  static_assert(Context::kMaxSubsteps == kMaxSubsteps);
  for (int k = 1; k <= kMaxSubsteps; ++k) bc.substepLength[k] = dt / k;  // the scalar path's h = dt / nsub
  bc.cellData = cellData_.data();
  bc.plateReach = plateReach_.empty() ? nullptr : plateReach_.data();
  bc.q = locator.constants();
  bc.grid = GridConstants(bc.q);
  bc.corners.set(locator.offsets32());
  for (int d = 0; d < 3; ++d) {
    bc.origin[d] = grid_.origin[d], bc.inv[d] = 1.0 / grid_.spacing[d], bc.spacing[d] = grid_.spacing[d];
    bc.last[d] = grid_.shape[d] - 1;
  }
  bc.sy = grid_.shape[0], bc.sz = grid_.shape[0] * grid_.shape[1];
  bc.noWall = walls ? 0.0 : 1e300;
  bc.halfDiagonal = 0.5 * grid_.spacing.norm();
  bc.midpoint = midpoint;
  if (walls && halfSpaces_.size() <= std::size_t(Context::kMaxHalfSpaces)) {
    bc.halfSpaces = int(halfSpaces_.size());
    for (int j = 0; j < bc.halfSpaces; ++j) {
      const auto& hs = halfSpaces_[std::size_t(j)];
      bc.hx[j] = hs.n.x(), bc.hy[j] = hs.n.y(), bc.hz[j] = hs.n.z(), bc.hc[j] = hs.c;
    }
    bc.margin = 2.0 * apparatus_.boundaryTolerance();
    if (!nearHalfSpaces_.empty()) bc.nearHalfSpaces = nearHalfSpaces_.data(), bc.nearReach2 = nearReach_ * nearReach_;
  }

  // The scalar path: free flight, and every tracer when the block path is off (tests compare both).
  // Counters go through `st`, not captured: a capture would bypass the OpenMP reduction's copies.
  auto moveOne = [&](std::int64_t i, std::int64_t cell, const Eigen::Vector3f& fluc, MotionStatistics& st) {
    Eigen::Vector3d p = cloud.position(std::size_t(i));
    Eigen::Vector3d v = cloud.velocity(std::size_t(i));
    // The first move of a tracer starts in `cell`: its clearance is known (walls on) or unused.
    const double firstClearance = walls ? double(clearance_[std::size_t(cell)]) : -1.0;
    if (settings_.freeFlight && sampler.alphaP(cell) < settings_.freeFlightAlpha) {
      // Free flight: implicit drag relaxation toward u_G^rec plus gravity, stable for any dt / tau.
      ++st.freeFlight;
      const StepFieldSampler gas(*gasVelocity_, locator);
      const int nsub = substepsFor(v.norm() * dt, st.substepCapped);
      const double h = dt / nsub;
      for (int s = 0; s < nsub; ++s) {
        const Eigen::Vector3d ug = gas.sample(p);
        const double re = (ug - v).norm() * reynoldsPerSpeed_;
        // Implicit in the drag: v' = (v + h (u_G / tau + g)) / (1 + h / tau), with 1 / tau = f / tau_Stokes.
        const double inverseTau = singleSphereDragFactor(re) * inverseStokesTime_;
        const double relaxation = 1.0 / (1.0 + h * inverseTau);
        v = (v + h * (ug * inverseTau + gravity_)) * relaxation;
        st.wallHits += moveWithWalls(p, h * v, &v, settings_.wallRestitution, s == 0 ? firstClearance : -1.0);
      }
      st.substeps += nsub - 1;
    } else {
      // u_P^rec in float at float grid coordinates, as the block path (block::locateGridBlock()).
      const StepFieldSampler up(*particleVelocity_, locator);
      const Eigen::Vector3f inverseSpacing = up.inverseSpacing();
      Eigen::Vector3f g = up.gridCoordinates(p);
      Eigen::Vector3f uf = up.sampleAtGrid(g) + fluc;  // Eq. (9)
      const int nsub = substepsFor(uf.cast<double>().norm() * dt, st.substepCapped);
      const double h = dt / nsub;
      for (int s = 0; s < nsub; ++s) {
        if (s > 0) g = up.gridCoordinates(p), uf = up.sampleAtGrid(g) + fluc;
        // Midpoint rule: Euler spirals outward in rotating flow (|x| grows by sqrt(1 + (omega h)^2)
        // per step); the midpoint velocity makes that error O((omega h)^4).
        if (midpoint) {
          const float half = float(0.5 * h);
          Eigen::Vector3f mid;
          for (int d = 0; d < 3; ++d) mid[d] = g[d] + half * (uf[d] * inverseSpacing[d]);
          uf = up.sampleAtGrid(mid) + fluc;
        }
        st.wallHits += moveWithWalls(p, h * uf.cast<double>(), nullptr, 1.0, s == 0 ? firstClearance : -1.0);
      }
      v = uf.cast<double>();
      st.substeps += nsub - 1;
    }
    cloud.setPosition(std::size_t(i), p);
    if (settings_.freeFlight) cloud.setVelocity(std::size_t(i), v);
  };

  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
  double* const px = cloud.x.data();
  double* const py = cloud.y.data();
  double* const pz = cloud.z.data();
  double* const pvx = cloud.vx.data();
  double* const pvy = cloud.vy.data();
  double* const pvz = cloud.vz.data();
  const float* cellData = cellData_.data();
  const std::int32_t* const ids = cloud.id.data();
  const bool streams = ctx.streamVelocity[0].size() == cloud.size();
  const float* const streamX = ctx.streamVelocity[0].data();
  const float* const streamY = ctx.streamVelocity[1].data();
  const float* const streamZ = ctx.streamVelocity[2].data();
  const bool vectorised = settings_.vectorised;
  // Dynamic chunks of blocks: sub-stepped and near-wall tracers cluster (in the spout, at the walls), so
  // equal shares of blocks are not equal work. Lanes with sub-steps left after their first are
  // deferred until 64 have gathered on the thread (or it has no chunk left) and move together. Blocks and
  // chunks are fixed, a lane's arithmetic does not depend on which lanes share its rounds, and counters
  // are integers, so results do not depend on which thread moves which chunk.
  bc.cloudX = px, bc.cloudY = py, bc.cloudZ = pz, bc.cloudVx = pvx, bc.cloudVy = pvy, bc.cloudVz = pvz;
  bc.keepVelocity = settings_.freeFlight;
  constexpr std::int64_t kChunk = 16;  // blocks
  std::int32_t* const nextCells = ctx.nextTracerCell.size() == cloud.size() ? ctx.nextTracerCell.data() : nullptr;
  const CellIndexer indexer(grid_);
  const std::int64_t chunks = (blocks + kChunk - 1) / kChunk;
  // `beside` on the team's last thread, which then takes what chunks are left (an exception is carried
  // out of the parallel region, which it must not leave).
  std::exception_ptr besideFailure;
  bc.nextCells = nextCells, bc.cellIndexer = &indexer;
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
  DeferredLanes deferred, deferredFree;
  BlockStencils stencils;
#pragma omp for schedule(dynamic, 1) nowait
  for (std::int64_t chunk = 0; chunk < chunks; ++chunk) {
    MotionStatistics st;
    for (std::int64_t b = chunk * kChunk; b < std::min(blocks, (chunk + 1) * kChunk); ++b) {
      const std::int64_t i0 = b * kBlock;
      const int count = int(std::min<std::int64_t>(kBlock, n - i0));
      alignas(64) float ax[kBlock], ay[kBlock], az[kBlock];  // u_fluc
      alignas(64) float speed[kBlock];
      alignas(64) float reachOf[kBlock];  // cellData_'s reach of the lane's cell (the first wall test)
      alignas(64) std::int32_t cellsFound[kBlock];
      std::int64_t free[kBlock];  // free flight (not bool, which stops the vectoriser)
      // The lanes' cells: those the last step found (read in place), or found here.
      const std::int32_t* cellOf = cellsFound;
      if (haveTracerAlpha) {
        cellOf = ctx.tracerCell.data() + i0;
      } else {
        indexer.cellsOf(count, px + i0, py + i0, pz + i0, cellsFound);
      }
      // `free` is read only where freeLanes > 0 (without free_flight, zeroing it was a memset per block).
      std::int64_t freeLanes = 0;
      if (settings_.freeFlight) {
        for (int k = 0; k < count; ++k) {
          free[k] = sampler.alphaP(cellOf[k]) < settings_.freeFlightAlpha;
          freeLanes += free[k];
        }
      }
      // A cell's reach and speed side by side: one 64-bit gather per lane for both (two 32-bit gathers
      // cost 1.7x as much on this machine).
  #pragma omp simd
      for (int k = 0; k < count; ++k) {
        std::uint64_t pair;
        std::memcpy(&pair, cellData + 2 * cellOf[k], sizeof pair);
        reachOf[k] = std::bit_cast<float>(std::uint32_t(pair));
        speed[k] = std::bit_cast<float>(std::uint32_t(pair >> 32));
      }
      if (freeLanes > 0) {  // none in free flight (a select: AVX2 has no vector int64-to-double conversion)
  #pragma omp simd
        for (int k = 0; k < count; ++k) speed[k] = free[k] != 0 ? 0.0f : speed[k];
      }
      // Eq. (10): u_fluc = |u_fluc| n_rand, n_rand from the tracer's counter-based stream.
      if (fluctuate) {
  #pragma omp simd
        for (int k = 0; k < count; ++k) {
          float nx, ny, nz;
          counterUnitVectorFloat(rngPrefix, std::uint64_t(ids[i0 + k]), nx, ny, nz);  // the tracer's own stream
          ax[k] = speed[k] * nx, ay[k] = speed[k] * ny, az[k] = speed[k] * nz;
        }
      } else {
        for (int k = 0; k < count; ++k) ax[k] = ay[k] = az[k] = 0.0f;
      }
      // The tracer's stream velocity relative to u_P^rec (velocity_streams), held over the step as u_fluc is.
      if (streams) {
  #pragma omp simd
        for (int k = 0; k < count; ++k) ax[k] += streamX[i0 + k], ay[k] += streamY[i0 + k], az[k] += streamZ[i0 + k];
      }
      if (!vectorised) {
        for (int k = 0; k < count; ++k) {
          moveOne(i0 + k, cellOf[k], Eigen::Vector3f(ax[k], ay[k], az[k]), st);
          ++st.scalarPath;
        }
      } else {
        // The lanes that follow u_P^rec: all of them, in place in the cloud's arrays (the velocity arrays
        // hold u as it is computed), unless some are in free flight.
        alignas(64) double h[kBlock];
        alignas(64) std::int32_t left[kBlock];
        // Lanes in free flight (or not) copied out of the cloud, and back (blocks with both kinds only).
        auto takeLanes = [&](bool freeFlying, LaneStorage& ls) {
          int j = 0;
          for (int k = 0; k < count; ++k) {
            if ((free[k] != 0) != freeFlying) continue;
            ls.x[j] = px[i0 + k], ls.y[j] = py[i0 + k], ls.z[j] = pz[i0 + k];
            ls.ux[j] = pvx[i0 + k], ls.uy[j] = pvy[i0 + k], ls.uz[j] = pvz[i0 + k];  // free flight's own velocity
            ls.ax[j] = freeFlying ? 0.0f : ax[k], ls.ay[j] = freeFlying ? 0.0f : ay[k], ls.az[j] = freeFlying ? 0.0f : az[k];
            ls.cell[j] = cellOf[k], ls.reach[j] = reachOf[k];
            ls.lane[j++] = k;
          }
          return ls.view(j, true);
        };
        auto putBack = [&](const Lanes& lanes, const LaneStorage& ls) {
          for (int j = 0; j < lanes.count; ++j) {
            const std::int64_t i = i0 + ls.lane[j];
            px[i] = lanes.x[j], py[i] = lanes.y[j], pz[i] = lanes.z[j];
            pvx[i] = lanes.ux[j], pvy[i] = lanes.uy[j], pvz[i] = lanes.uz[j];
          }
        };
        LaneStorage compact;
        // Velocities are kept in the cloud only for free flight, the one reader; otherwise they stay in the
        // block (saves writing 24 bytes per tracer-step).
        alignas(64) double sux[kBlock], suy[kBlock], suz[kBlock];
        const bool keep = settings_.freeFlight;
        Lanes L{px + i0, py + i0, pz + i0, ax, ay, az, keep ? pvx + i0 : sux, keep ? pvy + i0 : suy,
                keep ? pvz + i0 : suz, h, left, count, cellOf, reachOf};
        if (freeLanes > 0) L = takeLanes(false, compact);
        // Eq. (9): u_P^rec + u_fluc at the start, which sets the sub-steps (as substepsFor).
        sampleParticleVelocity(bc, L, stencils);
        auto countSubsteps = [&](Lanes& lanes) {
          return substepsOfBlock(lanes.ux, lanes.uy, lanes.uz, lanes.count, dt, inverseCellLimit, bc.substepLength,
                                 double(kMaxSubsteps), lanes.h, lanes.left, st.substeps, st.substepCapped);
        };
        const bool more = countSubsteps(L) > 0;
        subStep(L, stencils, true, bc, st);
        // The later sub-steps: in place when most lanes take them, else deferred.
        const bool inPlace = more && countLanesWithSubstepsLeft(L) >= kInPlaceLanes;
        if (inPlace) advanceInPlace(L, stencils, bc, st), ++st.blocksInPlace;
        // Copied back before deferring: deferring may finish lanes, whose results must not be overwritten.
        if (freeLanes > 0) putBack(L, compact);
        if (more && !inPlace) defer(L, i0, freeLanes > 0 ? compact.lane : nullptr, deferred, false, stencils, bc, st);
        if (freeLanes > 0) {
          // Free flight: the tracers' own velocities, sub-stepped by them.
          LaneStorage fs;
          Lanes F = takeLanes(true, fs);
          st.freeFlight += F.count;
          const bool moreFree = countSubsteps(F) > 0;
          freeFlightSubStep(F, stencils, bc, st);
          putBack(F, fs);
          if (moreFree) defer(F, i0, fs.lane, deferredFree, true, stencils, bc, st);
        }
      }
    }
    if (nextCells) {  // the chunk's new positions are still in cache: their cells, for the next step
      // (deferred lanes are between sub-steps: finishDeferred() writes their cells when it moves them)
      const std::int64_t first = chunk * kChunk * kBlock, last = std::min(n, (chunk + 1) * kChunk * kBlock);
      indexer.cellsOf(int(last - first), px + first, py + first, pz + first, nextCells + first);
    }
    addStatistics(st);
  }
  MotionStatistics st;
  finishDeferred(deferred, false, stencils, bc, st);
  finishDeferred(deferredFree, true, stencils, bc, st);
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
