#include "tracers/MotionKernel.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/Errors.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/FluctuationModel.hpp"
#include "tracers/UnitVectors.hpp"

namespace rcfd {
namespace {
/// Schiller-Naumann correction of Stokes drag, with the Newton regime constant beyond Re = 1000.
double dragFactor(double re) {
  return re < 1000.0 ? 1.0 + 0.15 * std::pow(re, 0.687) : 0.44 * re / 24.0;
}
}  // namespace

MotionKernel::MotionKernel(const TracerContext& ctx, const MotionSettings& settings)
    : settings_(settings), apparatus_(ctx.apparatus), grid_(ctx.grid) {
  // The block loops index the 4-float step field with int32 (4 x cells < 2^31).
  if (grid_.cellCount() > std::int64_t(1) << 29) {
    throw RunError("grid of " + std::to_string(grid_.cellCount()) + " cells: the tracer kernel supports at most 2^29");
  }
  minSpacing_ = grid_.spacing.minCoeff();
  const auto& p = ctx.scene.particles;
  const auto& g = ctx.scene.gas;
  particleDiameter_ = p.diameter;
  gasViscosity_ = g.kinematic_viscosity;
  stokesTime_ = p.density * p.diameter * p.diameter / (18.0 * g.density * g.kinematic_viscosity);
  if (settings_.walls) {
    // A point of cell c lies at most half a diagonal from its centre, so its wall distance is at least
    // sd(centre) - halfDiagonal: a move shorter than that cannot reach a wall (the fast path).
    // The block path uses the sharper per-point bound sd(p) >= sd(centre) - |p - centre| (signed
    // distances are 1-Lipschitz) against `reach`: sd(centre) less twice the band in which
    // firstIntersection() reports hits, so a move it accepts is one the exact test would not stop.
    const double halfDiagonal = 0.5 * grid_.spacing.norm();
    const double band = 2.0 * apparatus_.boundaryTolerance();
    clearance_.resize(std::size_t(grid_.cellCount()));
    reach_.resize(std::size_t(grid_.cellCount()));
#pragma omp parallel for schedule(static) if (grid_.cellCount() > kParallelThreshold)
    for (std::int64_t c = 0; c < grid_.cellCount(); ++c) {
      const auto ijk = grid_.cellIjk(c);
      const double sd = apparatus_.signedDistance(grid_.cellCenter(ijk[0], ijk[1], ijk[2]));
      // The factor 1 - 1e-6 covers the rounding to float (6e-8) and of the distances.
      clearance_[std::size_t(c)] = float(std::max(0.0, sd - halfDiagonal) * (1.0 - 1e-6));
      reach_[std::size_t(c)] = float(std::max(0.0, sd - band) * (1.0 - 1e-6));
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

void MotionKernel::prepare(const TracerContext& ctx, const FrameSampler& sampler, bool fluctuate) {
  const std::int64_t cells = grid_.cellCount();
  const bool parallel = cells > kParallelThreshold;
  particleVelocity_.build(sampler, false, parallel);
  if (settings_.freeFlight) gasVelocity_.build(sampler, true, parallel);
  cellData_.resize(2 * std::size_t(cells));
  const FluctuationModel* model = fluctuate ? settings_.fluctuation : nullptr;
  const double dt = ctx.dt;
#pragma omp parallel for schedule(static) if (parallel)
  for (std::int64_t c = 0; c < cells; ++c) {
    double speed = 0.0;
    if (model) {
      // Eq. (10), once per cell instead of once per tracer: it depends on the cell only.
      speed = std::min(model->speed(ctx.tracerAlpha[std::size_t(c)], sampler.alphaP(c), settings_.d0, dt),
                       settings_.uFlucMax);
    }
    cellData_[2 * std::size_t(c)] = settings_.walls ? reach_[std::size_t(c)] : 0.0f;
    cellData_[2 * std::size_t(c) + 1] = float(speed);
  }
}

namespace {
/// The 8 corners of the last stencil gathered from a step field: a sub-step's midpoint mostly lies in
/// the same block of cell centres as its start, and then needs no second gather.
class CornerCache {
 public:
  CornerCache(const StepVelocityField& field, const TrilinearLocator& locator) : field_(field), locator_(locator) {}
  Eigen::Vector3d sample(const TrilinearStencil& s) {
    if (s.base != base_) {
      field_.gather(s.base, locator_, corners_);
      base_ = s.base;
    }
    const Eigen::Array4d u = trilinear(corners_, s.f);
    return {u[0], u[1], u[2]};
  }
  Eigen::Vector3d sample(const Eigen::Vector3d& p) { return sample(locator_.locate(p)); }

 private:
  const StepVelocityField& field_;
  const TrilinearLocator& locator_;
  std::int64_t base_ = -1;
  Eigen::Array4d corners_[8];
};

/// Tracers processed together: the common case (one sub-step, no wall within reach, no free flight)
/// runs through loops over a block that the compiler vectorises; the rest takes the scalar path. Blocks
/// start at multiples of kBlock whatever the thread count, so each tracer takes the same path in the
/// same lane, and results stay bit-identical for any number of threads.
constexpr int kBlock = 64;

/// u at the points (x, y, z) of a block: trilinear in a step field of 4 floats per cell, plus (ax, ay, az).
void sampleBlock(const TrilinearLocator& locator, const float* field, int count, const double* x,
                 const double* y, const double* z, const double* ax, const double* ay, const double* az,
                 double* ux, double* uy, double* uz) {
  // Plain locals only: the vectoriser gives up on loads through `this` and on per-lane arrays.
  const TrilinearLocator::Constants q = locator.constants();
  const double ox = q.ox, oy = q.oy, oz = q.oz, ix = q.ix, iy = q.iy, iz = q.iz;
  const double lastX = q.lastX, lastY = q.lastY, lastZ = q.lastZ;
  const int maxX = q.maxX, maxY = q.maxY, maxZ = q.maxZ;
  const std::int32_t sy = q.sy, sz = q.sz;
  std::int32_t off[8];
  for (int c = 0; c < 8; ++c) off[c] = 4 * locator.offsets32()[c];
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    int lx, ly, lz;
    const double fx = TrilinearLocator::Constants::axis(x[k], ox, ix, lastX, maxX, lx);
    const double fy = TrilinearLocator::Constants::axis(y[k], oy, iy, lastY, maxY, ly);
    const double fz = TrilinearLocator::Constants::axis(z[k], oz, iz, lastZ, maxZ, lz);
    const float* c = field + 4 * (lx + ly * sy + lz * sz);
    // trilinear() of Trilinear.hpp written out on the corner loads (x, then y, then z).
    auto lerp = [&](int d) {
      const double x00 = c[off[0] + d] + fx * (double(c[off[1] + d]) - c[off[0] + d]);
      const double x10 = c[off[2] + d] + fx * (double(c[off[3] + d]) - c[off[2] + d]);
      const double x01 = c[off[4] + d] + fx * (double(c[off[5] + d]) - c[off[4] + d]);
      const double x11 = c[off[6] + d] + fx * (double(c[off[7] + d]) - c[off[6] + d]);
      const double y0 = x00 + fy * (x10 - x00);
      const double y1 = x01 + fy * (x11 - x01);
      return y0 + fz * (y1 - y0);
    };
    ux[k] = lerp(0) + ax[k];
    uy[k] = lerp(1) + ay[k];
    uz[k] = lerp(2) + az[k];
  }
}

}  // namespace

void MotionKernel::move(TracerContext& ctx) {
  stats_ = {};
  if (!settings_.transport) return;
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
  // Sub-steps so that no sub-step moves farther than max_courant cells; a non-finite or enormous
  // displacement gets kMaxSubsteps (the exact wall tests still keep the tracer inside).
  const double cellLimit = settings_.maxCourant * minSpacing_;
  auto substepsFor = [cellLimit](double distance, std::int64_t& cappedCount) -> int {
    const double courant = distance / cellLimit;
    if (!(courant <= double(kMaxSubsteps))) {
      ++cappedCount;
      return kMaxSubsteps;
    }
    return std::max(1, int(std::ceil(courant)));
  };
  const float* field = particleVelocity_.floats();
  const float* cellData = cellData_.data();
  const double noWall = settings_.walls ? 0.0 : 1e300;  // without walls every move is within reach
  struct {
    double origin[3], inv[3], spacing[3];
    int last[3];
    std::int32_t sy, sz;
  } g{};
  for (int d = 0; d < 3; ++d) {
    g.origin[d] = grid_.origin[d], g.inv[d] = 1.0 / grid_.spacing[d], g.spacing[d] = grid_.spacing[d];
    g.last[d] = grid_.shape[d] - 1;
  }
  g.sy = grid_.shape[0], g.sz = grid_.shape[0] * grid_.shape[1];
  const bool midpoint = settings_.midpoint;
  const bool walls = settings_.walls;
  const std::int64_t vectorised = settings_.vectorised ? 1 : 0;

  // The scalar path: sub-steps, walls within reach, free flight.
  // Counters go through `st`, not captured: a capture would bypass the OpenMP reduction's copies.
  auto moveOne = [&](std::int64_t i, std::int64_t cell, const Eigen::Vector3d& fluc, MotionStatistics& st) {
    Eigen::Vector3d p = cloud.position(std::size_t(i));
    Eigen::Vector3d v = cloud.velocity(std::size_t(i));
    // The first move of a tracer starts in `cell`: its clearance is known (walls on) or unused.
    const double firstClearance = walls ? double(clearance_[std::size_t(cell)]) : -1.0;
    if (settings_.freeFlight && sampler.alphaP(cell) < settings_.freeFlightAlpha) {
      // Free flight: implicit drag relaxation toward u_G^rec plus gravity, stable for any dt / tau.
      ++st.freeFlight;
      CornerCache gas(gasVelocity_, locator);
      const int nsub = substepsFor(v.norm() * dt, st.substepCapped);
      const double h = dt / nsub;
      for (int s = 0; s < nsub; ++s) {
        const Eigen::Vector3d ug = gas.sample(p);
        const double re = (ug - v).norm() * particleDiameter_ / gasViscosity_;
        const double tau = stokesTime_ / dragFactor(re);
        v = (v + h * (ug / tau + gravity_)) / (1.0 + h / tau);
        st.wallHits += moveWithWalls(p, h * v, &v, settings_.wallRestitution, s == 0 ? firstClearance : -1.0);
      }
      st.substeps += nsub - 1;
    } else {
      CornerCache up(particleVelocity_, locator);
      Eigen::Vector3d u = up.sample(p) + fluc;  // Eq. (9)
      const int nsub = substepsFor(u.norm() * dt, st.substepCapped);
      const double h = dt / nsub;
      for (int s = 0; s < nsub; ++s) {
        if (s > 0) u = up.sample(p) + fluc;
        // Midpoint rule: Euler spirals outward in rotating flow (|x| grows by sqrt(1 + (omega h)^2)
        // per step); the midpoint velocity makes that error O((omega h)^4).
        if (midpoint) u = up.sample(Eigen::Vector3d(p + 0.5 * h * u)) + fluc;
        st.wallHits += moveWithWalls(p, h * u, nullptr, 1.0, s == 0 ? firstClearance : -1.0);
      }
      v = u;
      st.substeps += nsub - 1;
    }
    cloud.setPosition(std::size_t(i), p);
    cloud.setVelocity(std::size_t(i), v);
  };

  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
  double* const px = cloud.x.data();
  double* const py = cloud.y.data();
  double* const pz = cloud.z.data();
#pragma omp parallel for schedule(static) reduction(+ : substeps, wallHits, freeFlight, capped, scalarPath, exactWallTests) if (n > kParallelThreshold)
  for (std::int64_t b = 0; b < blocks; ++b) {
    const std::int64_t i0 = b * kBlock;
    const int count = int(std::min<std::int64_t>(kBlock, n - i0));
    MotionStatistics st;
    alignas(64) double ax[kBlock], ay[kBlock], az[kBlock];  // u_fluc
    alignas(64) double ux[kBlock], uy[kBlock], uz[kBlock];  // u at the start (then at the midpoint)
    alignas(64) double mx[kBlock], my[kBlock], mz[kBlock];  // midpoint
    alignas(64) double speed[kBlock];
    std::int32_t cellOf[kBlock];
    // Flags (not bool, which stops the vectoriser): free flight; one sub-step; move final here.
    std::int64_t scalar[kBlock], single[kBlock], fast[kBlock];
    // Cells, then their clearance and Eq. (10) speed: independent loads the vectorised loop issues as
    // gathers, so their cache misses overlap.
    if (haveTracerAlpha) {
      for (int k = 0; k < count; ++k) cellOf[k] = ctx.tracerCell[std::size_t(i0 + k)];
    } else {
      for (int k = 0; k < count; ++k) cellOf[k] = std::int32_t(grid_.flatIndexOf(cloud.position(std::size_t(i0 + k))));
    }
    if (settings_.freeFlight) {
      for (int k = 0; k < count; ++k) scalar[k] = sampler.alphaP(cellOf[k]) < settings_.freeFlightAlpha;
    } else {
      for (int k = 0; k < count; ++k) scalar[k] = 0;
    }
#pragma omp simd
    for (int k = 0; k < count; ++k) {
      speed[k] = double(cellData[2 * cellOf[k] + 1]) * double(1 - scalar[k]);  // none in free flight
    }
    // Eq. (10): u_fluc = |u_fluc| n_rand, n_rand from the tracer's counter-based stream.
    if (fluctuate) {
#pragma omp simd
      for (int k = 0; k < count; ++k) {
        double nx, ny, nz;
        counterUnitVector(rngPrefix, std::uint64_t(i0 + k), nx, ny, nz);
        ax[k] = speed[k] * nx, ay[k] = speed[k] * ny, az[k] = speed[k] * nz;
      }
    } else {
      for (int k = 0; k < count; ++k) ax[k] = ay[k] = az[k] = 0.0;
    }
    const double* x = px + i0;
    const double* y = py + i0;
    const double* z = pz + i0;
    sampleBlock(locator, field, count, x, y, z, ax, ay, az, ux, uy, uz);  // Eq. (9)
    if (midpoint) {
      const double half = 0.5 * dt;
#pragma omp simd
      for (int k = 0; k < count; ++k) {
        mx[k] = x[k] + half * ux[k], my[k] = y[k] + half * uy[k], mz[k] = z[k] + half * uz[k];
      }
    }
    // One sub-step (|u| dt <= max_courant cells; the test of substepsFor) and a displacement shorter
    // than the cell's wall clearance: the move is final here.
    const double limit2 = cellLimit * cellLimit;
#pragma omp simd
    for (int k = 0; k < count; ++k) {
      const double d2 = (ux[k] * ux[k] + uy[k] * uy[k] + uz[k] * uz[k]) * (dt * dt);
      single[k] = (!scalar[k]) & (d2 <= limit2) & vectorised;
    }
    if (midpoint) sampleBlock(locator, field, count, mx, my, mz, ax, ay, az, ux, uy, uz);
    // Walls: |p - c| + |disp| < reach(c) for the centre c of p's cell keeps the whole move inside.
#pragma omp simd
    for (int k = 0; k < count; ++k) {
      const double dx = dt * ux[k], dy = dt * uy[k], dz = dt * uz[k];
      const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
      int ci[3];
      double off2 = 0.0;
      const double pk[3] = {x[k], y[k], z[k]};
      for (int d = 0; d < 3; ++d) {
        const double t = (pk[d] - g.origin[d]) * g.inv[d];
        const int i = int(t > 0.0 ? t : 0.0);
        ci[d] = i < g.last[d] ? i : g.last[d];
        const double e = pk[d] - (g.origin[d] + (double(ci[d]) + 0.5) * g.spacing[d]);
        off2 += e * e;
      }
      const double reach = double(cellData[2 * (ci[0] + ci[1] * g.sy + ci[2] * g.sz)]) + noWall;
      fast[k] = single[k] & (std::sqrt(off2) + length < reach);
    }
    double* const bx = px + i0;
    double* const by = py + i0;
    double* const bz = pz + i0;
    double* const bvx = cloud.vx.data() + i0;
    double* const bvy = cloud.vy.data() + i0;
    double* const bvz = cloud.vz.data() + i0;
#pragma omp simd
    for (int k = 0; k < count; ++k) {
      if (fast[k]) {  // masked stores
        bx[k] += dt * ux[k], by[k] += dt * uy[k], bz[k] += dt * uz[k];
        bvx[k] = ux[k], bvy[k] = uy[k], bvz[k] = uz[k];
      }
    }
    for (int k = 0; k < count; ++k) {
      if (fast[k]) continue;
      const std::int64_t i = i0 + k;
      if (single[k]) {
        // One sub-step with a wall within reach: the block's (midpoint) velocity, the exact wall test.
        Eigen::Vector3d p = cloud.position(std::size_t(i));
        const Eigen::Vector3d u(ux[k], uy[k], uz[k]);
        st.wallHits += moveWithWalls(p, dt * u, nullptr, 1.0, walls ? double(clearance_[std::size_t(cellOf[k])]) : -1.0);
        ++st.exactWallTests;
        cloud.setPosition(std::size_t(i), p);
        cloud.setVelocity(std::size_t(i), u);
      } else {
        moveOne(i, cellOf[k], Eigen::Vector3d(ax[k], ay[k], az[k]), st);
        ++st.scalarPath;
      }
    }
    substeps += st.substeps, wallHits += st.wallHits, freeFlight += st.freeFlight, capped += st.substepCapped;
    scalarPath += st.scalarPath, exactWallTests += st.exactWallTests;
  }
  stats_.substeps = substeps;
  stats_.wallHits = wallHits;
  stats_.freeFlight = freeFlight;
  stats_.substepCapped = capped;
  stats_.scalarPath = scalarPath;
  stats_.exactWallTests = exactWallTests;
}

}  // namespace rcfd
