#include "spray/ReferenceCoverage.hpp"

#include <cmath>
#include <numbers>

#include "analysis/ReferenceStatistics.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "spray/Coverage.hpp"
#include "spray/SprayState.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

/// The spray-stage effects the reference runs: the droplets and their deposition. `coverage` itself
/// only reports (Eq. (15) is applied to the collected droplets here), and the motion effects are the
/// CFD-DEM's.
const std::vector<std::string> kReferenceEffects = {"tracer_volume_fraction", "spray", "deposition"};

std::string stateGroup(const std::string& group, const std::string& effect) { return group + "/" + effect; }

}  // namespace

bool ReferenceCoverage::wanted(const Scene& scene) { return scene.hasEffect("coverage"); }

ReferenceCoverage::ReferenceCoverage(const Scene& scene, const Apparatus& apparatus, const CartesianGrid& grid,
                                     const std::vector<double>& openFraction, std::size_t parcels, double dt,
                                     std::uint64_t seed)
    : scene_(scene),
      dt_(dt),
      singleDropletCoverage_(singleDropletCoverage(scene.spray.droplet_diameter, scene.particles.diameter)),
      cloud_(std::make_unique<TracerCloud>(parcels)) {
  const double d = scene.particles.diameter;
  cloud_->particleVolume = std::numbers::pi / 6.0 * d * d * d;
  cloud_->particlesPerTracer = std::pow(scene.dem.coarse_graining, 3);
  context_ = std::make_unique<TracerContext>(scene, apparatus, nullptr, grid, *cloud_, seed);
  auto& ctx = *context_;
  ctx.dt = dt;
  ctx.openVolume.resize(openFraction.size());
  for (std::size_t c = 0; c < openFraction.size(); ++c) ctx.openVolume[c] = openFraction[c] * grid.cellVolume();
  effectNames_ = TracerEffectRegistry::resolve(kReferenceEffects);
  for (const auto& name : effectNames_) effects_.push_back(TracerEffectRegistry::entries().at(name).factory(ctx));
}

ReferenceCoverage::~ReferenceCoverage() = default;

void ReferenceCoverage::step(const std::vector<Eigen::Vector3d>& positions, const std::vector<std::uint64_t>& ids,
                             std::shared_ptr<const FieldFrame> fields) {
  auto& ctx = *context_;
  auto& cloud = *cloud_;
  if (positions.size() != cloud.size() || ids.size() != cloud.size()) {
    throw RunError("reference coverage: " + std::to_string(positions.size()) + " parcels, expected " +
                   std::to_string(cloud.size()));
  }
  // Index = permanent id: the hand-out of droplets within a cell runs in index order, and results are
  // written per parcel id.
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (ids[i] >= cloud.size()) throw RunError("reference coverage: parcel id " + std::to_string(ids[i]) + " out of range");
    cloud.setPosition(std::size_t(ids[i]), positions[i]);
  }
  ctx.frame = std::move(fields);
  ctx.nextFrame = nullptr;
  ctx.blend = 0.0;
  ctx.stepFields.invalidate();
  ctx.nextTracerCellStep = -1;  // the positions came from outside: count them afresh
  for (auto& e : effects_) e->beforeMove(ctx);
  for (auto& e : effects_) e->afterMove(ctx);
  ++ctx.step;
}

std::int64_t ReferenceCoverage::steps() const { return context_->step; }
double ReferenceCoverage::duration() const { return double(context_->step) * dt_; }

std::vector<double> ReferenceCoverage::dropletsPerParticle() const {
  const auto& collected = context_->spray->tracerDroplets;
  std::vector<double> out(collected.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = collected[i] / cloud_->particlesPerTracer;
  return out;
}

void ReferenceCoverage::save(h5::File& f, const std::string& group) const {
  f.write(group + "/step", std::vector<std::int64_t>{context_->step});
  for (std::size_t i = 0; i < effects_.size(); ++i) effects_[i]->saveState(f, stateGroup(group, effectNames_[i]));
}

void ReferenceCoverage::load(const h5::File& f, const std::string& group) {
  context_->step = f.readInt64s(group + "/step").at(0);
  for (std::size_t i = 0; i < effects_.size(); ++i) effects_[i]->loadState(f, stateGroup(group, effectNames_[i]));
  if (context_->spray->tracerDroplets.size() != cloud_->size()) {
    throw InputError(f.path(), group, "the reference coverage does not match the bed's parcels");
  }
}

void ReferenceCoverage::write(h5::File& db) const {
  namespace layout = analysis::reference_layout;
  db.write(layout::coverageDroplets, dropletsPerParticle());
  db.setAttribute(layout::coverageDroplets, layout::coverageDuration, duration());
  db.setAttribute(layout::coverageDroplets, layout::coverageDt, dt_);
  db.setAttribute(layout::coverageDroplets, layout::coverageParticlesPerParcel, cloud_->particlesPerTracer);
  db.setAttribute(layout::coverageDroplets, layout::coverageSingleDroplet, singleDropletCoverage_);
  const auto& s = *context_->spray;
  const auto& b = s.balance;
  db.write(layout::coverageBalance, std::vector<double>{b.injected, b.deposited, s.airborne(), b.oversprayWall,
                                                        b.oversprayOutlet, b.residual});
}

nlohmann::json ReferenceCoverage::summary() const {
  auto phi = dropletsPerParticle();
  for (double& v : phi) v = coverage(v, singleDropletCoverage_);
  const Distribution d = describe(std::move(phi), scene_.outputs.coverage_bins, 0.0, 1.0);
  const auto& b = context_->spray->balance;
  return {{"duration_s", duration()},
          {"dt_s", dt_},
          {"parcels", cloud_->size()},
          {"particles_per_parcel", cloud_->particlesPerTracer},
          {"mean", d.mean},
          {"median", d.median},
          {"p10", d.p10},
          {"p90", d.p90},
          {"overspray_fraction",
           b.injected > 0.0 ? (b.oversprayWall + b.oversprayOutlet) / b.injected : 0.0},
          {"deposited_fraction", b.injected > 0.0 ? b.deposited / b.injected : 0.0}};
}

}  // namespace rcfd
