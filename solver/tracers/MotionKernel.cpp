#include "tracers/MotionKernel.hpp"

#include <algorithm>
#include <cmath>

#include "tracers/CounterRng.hpp"
#include "tracers/FluctuationModel.hpp"

namespace rcfd {
namespace {
/// Schiller-Naumann correction of Stokes drag, with the Newton regime constant beyond Re = 1000.
double dragFactor(double re) {
  return re < 1000.0 ? 1.0 + 0.15 * std::pow(re, 0.687) : 0.44 * re / 24.0;
}
}  // namespace

MotionKernel::MotionKernel(const TracerContext& ctx, const MotionSettings& settings)
    : settings_(settings), apparatus_(ctx.apparatus), grid_(ctx.grid) {
  minSpacing_ = grid_.spacing.minCoeff();
  const auto& p = ctx.scene.particles;
  const auto& g = ctx.scene.gas;
  particleDiameter_ = p.diameter;
  gasViscosity_ = g.kinematic_viscosity;
  stokesTime_ = p.density * p.diameter * p.diameter / (18.0 * g.density * g.kinematic_viscosity);
  if (settings_.walls) {
    // A point of cell c lies at most half a diagonal from its centre, so its wall distance is at least
    // sd(centre) - halfDiagonal: a move shorter than that cannot reach a wall (the fast path).
    const double halfDiagonal = 0.5 * grid_.spacing.norm();
    clearance_.resize(std::size_t(grid_.cellCount()));
#pragma omp parallel for schedule(static) if (grid_.cellCount() > kParallelThreshold)
    for (std::int64_t c = 0; c < grid_.cellCount(); ++c) {
      const auto ijk = grid_.cellIjk(c);
      const double sd = apparatus_.signedDistance(grid_.cellCenter(ijk[0], ijk[1], ijk[2]));
      clearance_[std::size_t(c)] = float(std::max(0.0, sd - halfDiagonal) * (1.0 - 1e-6));
    }
  }
}

int MotionKernel::moveWithWalls(Eigen::Vector3d& p, Eigen::Vector3d disp, Eigen::Vector3d* velocity,
                                double restitution) const {
  if (!settings_.walls) {
    p += disp;
    return 0;
  }
  int bounces = 0;
  for (; bounces <= kMaxBounces; ++bounces) {
    const double length = disp.norm();
    if (!(length > 0.0)) return bounces;
    if (double(clearance_[std::size_t(grid_.flatIndexOf(p))]) > length) {
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

void MotionKernel::move(TracerContext& ctx) {
  stats_ = {};
  if (!settings_.transport) return;
  TracerCloud& cloud = ctx.cloud;
  const FrameSampler sampler = ctx.sampler();
  const double dt = ctx.dt;
  const bool haveTracerAlpha = !ctx.tracerAlpha.empty() && !ctx.tracerCell.empty();
  const std::int64_t n = std::int64_t(cloud.size());
  std::int64_t substeps = 0, wallHits = 0, freeFlight = 0, capped = 0;
  // Sub-steps so that no sub-step moves farther than max_courant cells; a non-finite or enormous
  // displacement gets kMaxSubsteps (the exact wall tests still keep the tracer inside).
  const double cellLimit = settings_.maxCourant * minSpacing_;
  auto substepsFor = [cellLimit](double distance, std::int64_t& cappedCount) {
    const double courant = distance / cellLimit;
    if (!(courant <= double(kMaxSubsteps))) {
      ++cappedCount;
      return kMaxSubsteps;
    }
    return std::max(1, int(std::ceil(courant)));
  };

#pragma omp parallel for schedule(static) reduction(+ : substeps, wallHits, freeFlight, capped) if (n > kParallelThreshold)
  for (std::int64_t i = 0; i < n; ++i) {
    Eigen::Vector3d p = cloud.position(std::size_t(i));
    Eigen::Vector3d v = cloud.velocity(std::size_t(i));
    const std::int64_t cell = haveTracerAlpha ? ctx.tracerCell[std::size_t(i)] : grid_.flatIndexOf(p);
    const double alphaRec = sampler.alphaP(cell);

    if (settings_.freeFlight && alphaRec < settings_.freeFlightAlpha) {
      // Free flight: implicit drag relaxation toward u_G^rec plus gravity, stable for any dt / tau.
      ++freeFlight;
      const int nsub = substepsFor(v.norm() * dt, capped);
      const double h = dt / nsub;
      for (int s = 0; s < nsub; ++s) {
        const Eigen::Vector3d ug = sampler.velocity(p, true);
        const double re = (ug - v).norm() * particleDiameter_ / gasViscosity_;
        const double tau = stokesTime_ / dragFactor(re);
        v = (v + h * (ug / tau + gravity_)) / (1.0 + h / tau);
        wallHits += moveWithWalls(p, h * v, &v, settings_.wallRestitution);
      }
      substeps += nsub - 1;
    } else {
      Eigen::Vector3d fluc = Eigen::Vector3d::Zero();
      if (settings_.fluctuation && haveTracerAlpha) {
        double speed = settings_.fluctuation->speed(ctx.tracerAlpha[std::size_t(cell)], alphaRec,
                                                    settings_.d0, dt);  // Eq. (10)
        speed = std::min(speed, settings_.uFlucMax);
        if (speed > 0.0) {
          CounterRng rng(ctx.seed, RngPurpose::Fluctuation, std::uint64_t(i), std::uint64_t(ctx.step));
          fluc = speed * rng.unitVector();
        }
      }
      Eigen::Vector3d u = sampler.velocity(p, false) + fluc;  // Eq. (9)
      const int nsub = substepsFor(u.norm() * dt, capped);
      const double h = dt / nsub;
      for (int s = 0; s < nsub; ++s) {
        if (s > 0) u = sampler.velocity(p, false) + fluc;
        // Midpoint rule: Euler spirals outward in rotating flow (|x| grows by sqrt(1 + (omega h)^2)
        // per step); the midpoint velocity makes that error O((omega h)^4).
        if (settings_.midpoint) u = sampler.velocity(p + 0.5 * h * u, false) + fluc;
        wallHits += moveWithWalls(p, h * u, nullptr, 1.0);
      }
      v = u;
      substeps += nsub - 1;
    }
    cloud.setPosition(std::size_t(i), p);
    cloud.setVelocity(std::size_t(i), v);
  }
  stats_.substeps = substeps;
  stats_.wallHits = wallHits;
  stats_.freeFlight = freeFlight;
  stats_.substepCapped = capped;
}

}  // namespace rcfd
