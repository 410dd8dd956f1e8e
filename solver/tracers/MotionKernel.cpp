#include "tracers/MotionKernel.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <cmath>
#include <exception>
#include <limits>
#include <string>

#include "core/Errors.hpp"
#include "geometry/WallClearance.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/FluctuationModel.hpp"
#include "tracers/BlockPath.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/SingleSphereDrag.hpp"
#include "tracers/UnitVectors.hpp"

namespace rcfd {

// move() reads a cell's [reach, speed] floats as one 64-bit word, reach in the low half.
static_assert(std::endian::native == std::endian::little);

MotionKernel::MotionKernel(const TracerContext& ctx, const MotionSettings& settings)
    : settings_(settings), apparatus_(ctx.apparatus), grid_(ctx.grid), reference_(ctx, settings) {
  selectIsa(kernelIsa());
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
  bc.exact = &reference_;
  return bc;
}

namespace block {
MoveTracers moveTracersFor(Isa isa) {
  switch (isa) {
#if defined(RCFD_NATIVE_BUILD)
    case Isa::native: return isa_native::moveTracers;
#else
    case Isa::avx2: return isa_avx2::moveTracers;
    case Isa::avx512: return isa_avx512::moveTracers;
#endif
    default: throw RunError(std::string("the motion kernel has no ") + isaName(isa) + " variant in this build");
  }
}
}  // namespace block

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
  in.tracers = n;
  in.freeFlight = settings_.freeFlight;
  in.freeFlightAlpha = settings_.freeFlightAlpha;
  moveTracers_(in, beside, stats_);
  if (nextCells) ctx.nextTracerCellStep = ctx.step + 1;
}

void MotionKernel::selectIsa(Isa isa) {
  moveTracers_ = block::moveTracersFor(isa);
  isa_ = isa;
}

}  // namespace rcfd
