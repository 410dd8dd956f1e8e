#include "tracers/ReferenceMotion.hpp"

#include <algorithm>
#include <cmath>

#include "tracers/CellIndex.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/FluctuationModel.hpp"
#include "tracers/FrameSampler.hpp"
#include "tracers/SingleSphereDrag.hpp"
#include "tracers/StepField.hpp"
#include "tracers/UnitVectors.hpp"

namespace rcfd {

ReferenceMotion::ReferenceMotion(const TracerContext& ctx, const MotionSettings& settings)
    : settings_(settings), apparatus_(ctx.apparatus), grid_(ctx.grid) {
  inverseCellLimit_ = 1.0 / (settings_.maxCourant * grid_.spacing.minCoeff());
  const auto& p = ctx.scene.particles;
  const auto& g = ctx.scene.gas;
  reynoldsPerSpeed_ = p.diameter / g.kinematic_viscosity;
  inverseStokesTime_ = 18.0 * g.density * g.kinematic_viscosity / (p.density * p.diameter * p.diameter);
}

int ReferenceMotion::substepsFor(double distance, std::int64_t& capped) const {
  const double courant = distance * inverseCellLimit_;
  if (!(courant <= double(kMaxSubsteps))) {  // also a non-finite distance
    ++capped;
    return kMaxSubsteps;
  }
  return std::max(1, int(std::ceil(courant)));
}

int ReferenceMotion::moveReflecting(Eigen::Vector3d& p, Eigen::Vector3d disp, Eigen::Vector3d* velocity,
                                    double restitution) const {
  if (!settings_.walls) {
    p += disp;
    return 0;
  }
  int bounces = 0;
  for (; bounces <= kMaxBounces; ++bounces) {
    if (!(disp.norm() > 0.0)) return bounces;
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

void ReferenceMotion::move(TracerContext& ctx, MotionStatistics& stats) const {
  if (!settings_.transport) return;
  TracerCloud& cloud = ctx.cloud;
  const FrameSampler sampler = ctx.sampler();
  const StepVelocityField& particleVelocity = ctx.stepVelocity(false);
  const StepVelocityField* gasVelocity = settings_.freeFlight ? &ctx.stepVelocity(true) : nullptr;
  const double dt = ctx.dt;
  const CounterRngPrefix rngPrefix(ctx.seed, RngPurpose::Fluctuation, std::uint64_t(ctx.step));
  const bool streams = ctx.streamVelocity[0].size() == cloud.size();
  const std::int64_t n = std::int64_t(cloud.size());
  std::int64_t substeps = 0, wallHits = 0, freeFlight = 0, capped = 0;
  // Cells as tracer_volume_fraction finds them (CellIndexer: one function for every user of a tracer's
  // cell, so a cell does not depend on who found it): the step's own where it mapped the tracers.
  const CellIndexer indexer(grid_);
  const bool haveCells = ctx.tracerCell.size() == cloud.size();
  const bool writeNextCells = ctx.nextTracerCell.size() == cloud.size();
  const bool fluctuate = settings_.fluctuation && !ctx.tracerAlpha.empty() && haveCells;
  auto cellOf = [&indexer](const Eigen::Vector3d& x) {
    std::int32_t c;
    indexer.cellsOf(1, &x.x(), &x.y(), &x.z(), &c);
    return std::int64_t(c);
  };

  // Eq. (10)'s speed in cell c: the model's, capped, for the tracers' and the recurrence fields' alpha_P
  // (the latter blended between two frames where the step lies between them).
  const FieldFrame& frame = sampler.frame();
  const FieldFrame* next = sampler.nextFrame();
  auto fluctuationSpeed = [&](std::int64_t c) -> float {
    const float alphaTracer = ctx.tracerAlpha[std::size_t(c)];
    if (!(alphaTracer > 0.0f)) return 0.0f;
    const double a = double(frame.alpha_p[std::size_t(c)]);
    const double rec = next ? a + sampler.blend() * (double(next->alpha_p[std::size_t(c)]) - a) : a;
    return float(std::min(settings_.fluctuation->speed(alphaTracer, rec, settings_.d0, dt), settings_.uFlucMax));
  };

#pragma omp parallel for schedule(static) reduction(+ : substeps, wallHits, freeFlight, capped)
  for (std::int64_t i = 0; i < n; ++i) {
    Eigen::Vector3d p = cloud.position(std::size_t(i));
    Eigen::Vector3d v = cloud.velocity(std::size_t(i));
    const std::int64_t cell = haveCells ? std::int64_t(ctx.tracerCell[std::size_t(i)]) : cellOf(p);
    if (settings_.freeFlight && sampler.alphaP(cell) < settings_.freeFlightAlpha) {
      // Free flight: v' = (v + h (u_G / tau + g)) / (1 + h / tau), implicit in the drag, 1 / tau =
      // f(Re) / tau_Stokes.
      ++freeFlight;
      const StepFieldSampler gas(*gasVelocity, sampler.locator());
      const int nsub = substepsFor(v.norm() * dt, capped);
      const double h = dt / nsub;
      for (int s = 0; s < nsub; ++s) {
        const Eigen::Vector3d ug = gas.sample(p);
        const double re = (ug - v).norm() * reynoldsPerSpeed_;
        const double inverseTau = singleSphereDragFactor(re) * inverseStokesTime_;
        const double relaxation = 1.0 / (1.0 + h * inverseTau);
        v = (v + h * (ug * inverseTau + gravity_)) * relaxation;
        wallHits += moveReflecting(p, h * v, &v, settings_.wallRestitution);
      }
      substeps += nsub - 1;
    } else {
      // Eq. (10): u_fluc = |u_fluc| n, n from the tracer's own stream; plus the stream velocity.
      Eigen::Vector3f fluc = Eigen::Vector3f::Zero();
      if (fluctuate) {
        float nx, ny, nz;
        counterUnitVectorFloat(rngPrefix, std::uint64_t(cloud.id[std::size_t(i)]), nx, ny, nz);
        const float speed = fluctuationSpeed(cell);
        fluc = {speed * nx, speed * ny, speed * nz};
      }
      if (streams) {
        fluc += Eigen::Vector3f(ctx.streamVelocity[0][std::size_t(i)], ctx.streamVelocity[1][std::size_t(i)],
                                ctx.streamVelocity[2][std::size_t(i)]);
      }
      // Eq. (9): dx/dt = u_P^rec(x) + u_fluc.
      const StepFieldSampler up(particleVelocity, sampler.locator());
      const Eigen::Vector3f inverseSpacing = up.inverseSpacing();
      Eigen::Vector3f g = up.gridCoordinates(p);
      Eigen::Vector3f u = up.sampleAtGrid(g) + fluc;
      const int nsub = substepsFor(u.cast<double>().norm() * dt, capped);
      const double h = dt / nsub;
      for (int s = 0; s < nsub; ++s) {
        if (s > 0) g = up.gridCoordinates(p), u = up.sampleAtGrid(g) + fluc;
        // Midpoint rule: Euler spirals outward in rotating flow (|x| grows by sqrt(1 + (omega h)^2) per
        // step); the midpoint velocity makes that error O((omega h)^4).
        if (settings_.midpoint) {
          const float half = float(0.5 * h);
          Eigen::Vector3f mid;
          for (int d = 0; d < 3; ++d) mid[d] = g[d] + half * (u[d] * inverseSpacing[d]);
          u = up.sampleAtGrid(mid) + fluc;
        }
        wallHits += moveReflecting(p, h * u.cast<double>(), nullptr, 1.0);
      }
      v = u.cast<double>();
      substeps += nsub - 1;
    }
    cloud.setPosition(std::size_t(i), p);
    if (settings_.freeFlight) cloud.setVelocity(std::size_t(i), v);
    if (writeNextCells) ctx.nextTracerCell[std::size_t(i)] = std::int32_t(cellOf(p));
  }
  if (writeNextCells) ctx.nextTracerCellStep = ctx.step + 1;
  stats.substeps += substeps, stats.wallHits += wallHits, stats.freeFlight += freeFlight;
  stats.substepCapped += capped, stats.scalarPath += n;
}

}  // namespace rcfd
