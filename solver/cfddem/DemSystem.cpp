#include "cfddem/DemSystem.hpp"
#include "cfddem/DemParallel.hpp"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <omp.h>
#include <spdlog/spdlog.h>
#include <stdexcept>

#include "core/Errors.hpp"

namespace rcfd {

using Eigen::Vector3d;

namespace {
double seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

DemSettings DemSystem::settingsFromScene(const Scene& scene) {
  DemSettings s;
  s.time_step = scene.dem.time_step;
  s.max_rayleigh_fraction = scene.dem.max_rayleigh_fraction;
  s.max_overlap_fraction = scene.dem.max_overlap_fraction;
  s.rolling_model = scene.hasEffect("rolling_friction") ? "cdt" : "";
  return s;
}

DemSystem::DemSystem(const DemMaterial& material, DemWalls walls, const DemSettings& settings)
    : material_(material), walls_(std::move(walls)), settings_(settings),
      list_(settings.skin_fraction * material.particle_radius) {
  rayleigh_fraction_ = checkTimeStep(material_, settings_.time_step, settings_.max_rayleigh_fraction);
  spdlog::info("DEM: dt = {:.4g} s is {:.3f} of the Rayleigh time {:.4g} s (parcel radius {:.4g} m)",
               settings_.time_step, rayleigh_fraction_, material_.rayleighTime(),
               material_.particle_radius);
  try {
    model_ = ContactModelRegistry::create(settings_.contact_model, material_);
    if (!settings_.rolling_model.empty())
      rolling_ = RollingModelRegistry::create(settings_.rolling_model, material_);
  } catch (const std::out_of_range& e) {
    throw InputError("scene", settings_.rolling_model.empty() ? "/dem/contact_model" : "/effects",
                     e.what());
  }
  model_->setRollingModel(rolling_.get());
}

std::size_t DemSystem::addParticle(const Vector3d& x, const Vector3d& v) {
  const std::size_t i = particles_.add(x, v, material_.particle_radius, material_.density);
  // Until the next force evaluation a new particle feels gravity only (it is inserted clear of
  // others); the particles already there keep their forces, so no contact history is advanced twice.
  particles_.force[i] = particles_.mass[i] * settings_.gravity + particles_.fluid_force[i];
  particles_.torque[i].setZero();
  return i;
}

void DemSystem::resizeState() {
  wall_history_.resize(particles_.size());
}

void DemSystem::sortParticles() {
  DemParticles& p = particles_;
  const std::size_t n = p.size();
  if (n == 0) return;
  Vector3d lo = p.x[0], hi = p.x[0];
  double r_max = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(p.x[i]);
    hi = hi.cwiseMax(p.x[i]);
    r_max = std::max(r_max, p.radius[i]);
  }
  // Cells of the list's size, ordered x fastest, then z, then y (layers of a bed); ties keep the
  // current order, so the permutation depends on the positions only (deterministic).
  const double cell = 2.0 * r_max + list_.skin();
  long nc[3];
  for (int a = 0; a < 3; ++a)
    nc[a] = std::clamp(static_cast<long>((hi[a] - lo[a]) / cell) + 1, 1L, 1L << 20);
  std::vector<std::uint64_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    long c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(static_cast<long>((p.x[i][a] - lo[a]) / cell), 0L, nc[a] - 1);
    key[i] = (static_cast<std::uint64_t>(c[1]) * nc[2] + c[2]) * nc[0] + c[0];
  }
  std::vector<std::size_t> perm(n);
  for (std::size_t i = 0; i < n; ++i) perm[i] = i;
  std::stable_sort(perm.begin(), perm.end(),
                   [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  p.permute(perm);
  list_.permute(perm);
  const int slots = WallHistory::slots;
  WallHistory h;
  h.resize(n);
  for (std::size_t k = 0; k < n; ++k)
    for (int s = 0; s < slots; ++s) {
      h.wall[k * slots + s] = wall_history_.wall[perm[k] * slots + s];
      h.shear[k * slots + s] = wall_history_.shear[perm[k] * slots + s];
    }
  wall_history_ = std::move(h);
}

void DemSystem::computeForces(bool final_kick, int moved) {
  if (wall_history_.wall.size() != particles_.size() * WallHistory::slots) resizeState();
  const bool rebuild = moved < 0 ? list_.needsRebuild(particles_)
                                 : (moved > 0 || list_.positionsAtBuild().size() != particles_.size());
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  if (rebuild) {
    if (settings_.sort_interval > 0 && static_cast<long>(particles_.size()) >= kDemSortMinParticles &&
        builds_since_sort_++ % settings_.sort_interval == 0) {
      sortParticles();  // at the first build, then every sort_interval builds
    }
    list_.build(particles_, walls_);
    pair_forces_.resize(list_.pairs());
  }
  const auto t1 = Clock::now();
  // The set-up evaluation before the first step does not advance the tangential history (as
  // LIGGGHTS' setup with shearupdate off).
  ContactContext ctx{particles_, list_, walls_, wall_history_, pair_forces_,
                     forces_valid_ ? settings_.time_step : 0.0};
  const long n = static_cast<long>(particles_.size());
  const Vector3d g = settings_.gravity;
  const double h = 0.5 * settings_.time_step;
  DemParticles& p = particles_;
  ctx.direct = settings_.serial_direct_accumulation && omp_get_max_threads() == 1;
  if (ctx.direct)
    for (long i = 0; i < n; ++i) {
      p.force[i] = p.mass[i] * g + p.fluid_force[i];
      p.torque[i].setZero();
    }
  model_->computePairs(ctx);
  const auto t2 = Clock::now();
  const bool gather_pairs = !ctx.direct;
  double max_overlap = 0.0;
  long wall_contacts = 0;
  // Gather in a fixed order (gravity + fluid force + own row, then pairs as second member, then walls):
  // independent of the thread count. The second half kick of velocity Verlet is fused into the same loop.
#pragma omp parallel for schedule(static) reduction(max : max_overlap) reduction(+ : wall_contacts) if (n >= kDemParallelMinParticles)
  for (long i = 0; i < n; ++i) {
    Vector3d f, t;
    if (gather_pairs) {
      f = p.mass[i] * g + p.fluid_force[i] + p.force[i];  // own row, summed by the pair loop
      t = p.torque[i];
      for (auto c = list_.col_start[i]; c < list_.col_start[i + 1]; ++c) {
        const auto q = list_.col_pair[c];
        if (!pair_forces_.active[q]) continue;
        f -= pair_forces_.force[q];
        t += pair_forces_.torque_j[q];
      }
    } else {
      f = p.force[i];
      t = p.torque[i];
    }
    if (list_.wall_start[i] != list_.wall_start[i + 1])
      model_->computeWalls(ctx, i, f, t, max_overlap, wall_contacts);
    p.force[i] = f;
    p.torque[i] = t;
    if (final_kick) {
      p.v[i] += (h * p.inv_mass[i]) * f;
      p.omega[i] += (h * p.inv_inertia[i]) * t;
    }
  }
  timings_.build += seconds(t0, t1);
  timings_.pairs += seconds(t1, t2);
  timings_.gather += seconds(t2, Clock::now());
  ctx.max_overlap_fraction = std::max(ctx.max_overlap_fraction, max_overlap);
  ctx.wall_contacts += wall_contacts;
  stats_ = DemStepStats{ctx.max_overlap_fraction, ctx.contacts, ctx.wall_contacts};
  if (ctx.max_overlap_fraction > max_overlap_seen_) max_overlap_seen_ = ctx.max_overlap_fraction;
  if (!overlap_warned_ && ctx.max_overlap_fraction > settings_.max_overlap_fraction) {
    overlap_warned_ = true;
    spdlog::warn("DEM: an overlap reached {:.3g} of the radius at t = {:.4g} s, above "
                 "/dem/max_overlap_fraction {:.3g} (Lommen et al.): stiffer particles or slower "
                 "impacts keep the Hertz model accurate (warned once per run)",
                 ctx.max_overlap_fraction, time_, settings_.max_overlap_fraction);
  }
  forces_valid_ = true;
}

void DemSystem::step() {
  if (!forces_valid_) computeForces(false, -1);
  const double dt = settings_.time_step, h = 0.5 * dt;
  const long n = static_cast<long>(particles_.size());
  DemParticles& p = particles_;
  // The list's displacement test is fused into the drift: one pass, one barrier.
  const auto& x_build = list_.positionsAtBuild();
  const bool have_build = x_build.size() == p.size();
  const double limit2 = list_.rebuildDistance2();
  int moved = have_build ? 0 : 1;
  const auto t0 = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static) reduction(| : moved) if (n >= kDemParallelMinParticles)
  for (long i = 0; i < n; ++i) {
    p.v[i] += (h * p.inv_mass[i]) * p.force[i];
    p.omega[i] += (h * p.inv_inertia[i]) * p.torque[i];
    p.x[i] += dt * p.v[i];
    if (have_build) moved |= (p.x[i] - x_build[i]).squaredNorm() > limit2 ? 1 : 0;
  }
  timings_.drift += seconds(t0, std::chrono::steady_clock::now());
  computeForces(true, moved);
  time_ += dt;
  ++steps_;
}

void DemSystem::run(long steps) {
  for (long s = 0; s < steps; ++s) step();
}

double DemSystem::elasticEnergy() const {
  const DemParticles& p = particles_;
  double e = 0.0;
  auto hertz = [](const ContactParams& c, double r_eff, double delta) {
    return 8.0 / 15.0 * c.y_eff * std::sqrt(r_eff) * std::pow(delta, 2.5);
  };
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (auto q = list_.row_start.empty() ? 0 : list_.row_start[i];
         !list_.row_start.empty() && q < list_.row_start[i + 1]; ++q) {
      const auto k = list_.j[q];
      const double delta = p.radius[i] + p.radius[k] - (p.x[i] - p.x[k]).norm();
      if (delta > 0.0)
        e += hertz(material_.particle_particle, p.radius[i] * p.radius[k] / (p.radius[i] + p.radius[k]),
                   delta);
    }
    for (std::size_t k = 0; k < walls_.size(); ++k) {
      WallContact wc;
      if (walls_.contact(k, p.x[i], p.radius[i], wc))
        e += hertz(material_.particle_wall, p.radius[i], p.radius[i] - wc.distance);
    }
  }
  return e;
}

double DemSystem::totalEnergy() const {
  return particles_.kineticEnergy() + particles_.gravityPotential(settings_.gravity) + elasticEnergy();
}

}  // namespace rcfd
