// The built-in CFD-DEM driver: DEM, gas and their coupling step by step (CfdDemSimulation.hpp).

#include "cfddem/CfdDemSimulation.hpp"

#include <algorithm>
#include <cmath>
#include <spdlog/spdlog.h>
#include <sstream>

#include "cfddem/ApparatusWalls.hpp"
#include "cfddem/coupling/FluidCoupling.hpp"
#include "cfddem/coupling/VolumeMapping.hpp"
#include "cfddem/gas/GasSolver.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "geometry/ThinWalls.hpp"

namespace rcfd {

/// Gas steps beyond the planned ones that one coupling step may take when the gas speeds up within it.
constexpr int kMaxExtraGasSteps = 100000;

struct CfdDemSimulation::Coupling {
  std::unique_ptr<coupling::FluidCoupling> fluid;     ///< with gas
  std::unique_ptr<coupling::VolumeMapping> mapping;   ///< without gas: alpha_P and u_P on demand
  const coupling::VolumeMapping& map() const { return fluid ? fluid->mapping() : *mapping; }
};

CfdDemSimulation::CfdDemSimulation(const Scene& scene, std::uint64_t seed)
    : CfdDemSimulation(scene, seed, gas::GasOptions{}) {}

CfdDemSimulation::CfdDemSimulation(const Scene& scene, std::uint64_t seed, const gas::GasOptions& gasOptions)
    : scene_(scene), seed_(seed), apparatus_(std::make_unique<Apparatus>(scene.apparatus)),
      grid_(makeGrid(*apparatus_, scene.grid)) {
  const DemSettings settings = DemSystem::settingsFromScene(scene_);
  dem_ = std::make_unique<DemSystem>(DemMaterial::fromScene(scene_), wallsFromApparatus(*apparatus_), settings);
  coupling_ = std::make_unique<Coupling>();
  if (scene_.hasEffect("gas")) {
    gas::GasOptions options = gasOptions;
    options.gravity = settings.gravity;  // hydrostatic pressure: buoyancy through -V_p grad p
    gas_ = std::make_unique<gas::GasSolver>(scene_, *apparatus_, grid_, options);
    coupling::FluidCouplingOptions fo;
    fo.drag = scene_.hasEffect("drag");
    fo.smoothingLength = scene_.hasEffect("smoothing") ? scene_.gas.smoothing_length : 0.0;
    coupling_->fluid = std::make_unique<coupling::FluidCoupling>(scene_, *gas_, *dem_, fo);
  } else {
    if (scene_.hasEffect("drag") || scene_.hasEffect("smoothing"))
      spdlog::warn("CFD-DEM: effects drag and smoothing act through the gas phase; without the effect gas they "
                   "do nothing");
    std::vector<double> phi = openFractions(*apparatus_, grid_);
    std::vector<char> usable(phi.size());
    for (std::size_t c = 0; c < phi.size(); ++c) usable[c] = phi[c] > 0 ? 1 : 0;
    coupling_->mapping = std::make_unique<coupling::VolumeMapping>(grid_, std::move(phi), std::move(usable),
                                                                   thinWallBaffles(*apparatus_, grid_));
  }
}

CfdDemSimulation::~CfdDemSimulation() = default;

FillResult CfdDemSimulation::fillAndSettle(const std::function<bool()>& stopRequested,
                                           const std::function<void(FillStage)>& stageStarted,
                                           const std::function<void(FillStage, double)>& progress) {
  FillOptions options;
  options.seed = seed_;
  options.stop_requested = stopRequested;
  options.stage_started = stageStarted;
  options.progress = progress;
  options.max_settle_time = scene_.dem.settle_time;
  options.inside = [this](const Eigen::Vector3d& x) { return apparatus_->signedDistance(x) > 0.0; };
  const FillResult r = rcfd::fillAndSettle(*dem_, defaultFillRegion(scene_.apparatus), parcelsForBedMass(scene_), options);
  demStep_ = dem_->steps();
  lastInterval_ = 0.0;  // the gas starts from here: no rate of change of alpha_G yet
  return r;
}

long CfdDemSimulation::fillFallSteps() const { return fallStepsPerBatch(*dem_, defaultFillRegion(scene_.apparatus)); }

void CfdDemSimulation::setFlowFactor(double factor) {
  if (!(factor >= 0.0 && factor <= 1.0))
    throw RunError("CFD-DEM: flow factor " + std::to_string(factor) + " is outside [0, 1]");
  if (gas_) gas_->setFlowFactor(factor);
}

const CfdDemStepStats& CfdDemSimulation::step(std::int64_t untilDemStep) {
  if (untilDemStep <= demStep_)
    throw RunError("CFD-DEM: step(" + std::to_string(untilDemStep) + ") is not after the current DEM step " +
                   std::to_string(demStep_));
  const double dtDem = dem_->timeStep();
  const std::int64_t left = untilDemStep - demStep_;
  std::int64_t k = std::min<std::int64_t>(scene_.dem.coupling_interval, left);
  last_ = CfdDemStepStats{};
  checkParcels();  // a parcel changed from outside (or a bad checkpoint) is named before the gas sees it
  if (gas_) {
    coupling_->fluid->prepare(lastInterval_);
    // The gas step is a whole number of DEM steps, as long as the CFL (and source) limit allows;
    // a limit below dt_DEM splits that one DEM step into several equal gas steps.
    const double stable = gas_->stableTimeStep();
    const std::int64_t kCfl = std::int64_t(std::floor(stable / dtDem * (1.0 + 1e-12)));
    k = std::max<std::int64_t>(1, std::min(k, kCfl));
    const double dt = double(k) * dtDem;
    const int gasSteps = std::max(1, int(std::ceil(dt / stable * (1.0 - 1e-12))));
    // One gas step of at most h; a failure of the gas's own (the residual, a non-finite velocity) is
    // reported with when it happened.
    auto gasStep = [&](double h) {
      double taken = 0.0;
      try {
        taken = gas_->step(h);
      } catch (const RunError& e) {
        std::ostringstream m;
        m << "CFD-DEM at t = " << time() << " s (DEM step " << demStep_ << ", gas step of " << h << " s): " << e.what();
        throw RunError(m.str());
      }
      last_.pressureIterations += gas_->lastStep().pressureIterations;
      return taken;
    };
    double left = dt;  // of the coupling step still to cover with gas steps
    for (int s = 0; s < gasSteps; ++s) {
      const double h = dt / gasSteps;
      const double taken = gasStep(h);
      left -= taken;
      if (taken < h * (1.0 - 1e-12)) break;  // the gas velocity grew within the coupling step: see below
      left = dt - double(s + 1) * h;
    }
    // A CFL limit that fell within the coupling step (the gas sped up) is met by further, shorter gas
    // steps until the step's time is covered; the DEM side is unchanged.
    for (int extra = 0; left > 1e-12 * dt; ++extra) {
      if (extra >= kMaxExtraGasSteps) {
        std::ostringstream m;
        m << "CFD-DEM: the gas step fell below " << dt / kMaxExtraGasSteps << " s at t = " << time()
          << " s (DEM step " << demStep_ << "): the gas velocity grows without bound";
        throw RunError(m.str());
      }
      left -= gasStep(left);
    }
    coupling_->fluid->applyForces();
    last_.courant = gas_->lastStep().courant;
    last_.maxAlphaP = coupling_->fluid->maxParticleFraction();
  }
  dem_->run(long(k));
  demStep_ += k;
  last_.demSteps = int(k);
  last_.dt = double(k) * dtDem;
  lastInterval_ = last_.dt;
  checkParcels();
  return last_;
}

void CfdDemSimulation::checkParcels() const {
  const DemParticles& p = dem_->particles();
  const Eigen::Vector3d lower = apparatus_->lowerCorner(), upper = apparatus_->upperCorner();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p.x[i].allFinite() || !p.v[i].allFinite()) {
      std::ostringstream m;
      m << "CFD-DEM: parcel " << p.id[i] << " has a non-finite position or velocity at t = " << time()
        << " s (DEM step " << demStep_ << "), at x = (" << p.x[i].transpose() << ")";
      throw RunError(m.str());
    }
    // A parcel whose centre left the chamber's bounding box passed a wall within one DEM step: it moved
    // so far per step that its wall contact was never resolved. The scene's DEM step is too long for the
    // speeds the gas gives the parcels (the Rayleigh criterion bounds the contact stiffness, not the
    // speed).
    if (((p.x[i] - lower).array() < 0.0).any() || ((upper - p.x[i]).array() < 0.0).any()) {
      const double dt = dem_->timeStep(), speed = p.v[i].norm(), r = p.radius[i];
      std::ostringstream m;
      m.precision(3);
      m << "parcel " << p.id[i] << " left the chamber at t = " << time() << " s (DEM step " << demStep_
        << ") moving at " << speed << " m/s: " << dt << " s moves it " << speed * dt / r
        << " radii a step, too far for its wall contacts; at most " << (speed > 0.0 ? 0.5 * r / speed : dt)
        << " s (half a radius a step at that speed) keeps them resolved";
      throw InputError("scene", "/dem/time_step", m.str());
    }
  }
}

std::int64_t CfdDemSimulation::demStep() const { return demStep_; }
double CfdDemSimulation::time() const { return double(demStep_) * dem_->timeStep(); }
double CfdDemSimulation::demTimeStep() const { return dem_->timeStep(); }

const coupling::FluidCoupling* CfdDemSimulation::fluidCoupling() const { return coupling_->fluid.get(); }

std::vector<double> CfdDemSimulation::particleFraction() const {
  // From the current parcels (the coupling's own field is that of the start of the last coupling
  // step), so a sampled frame's alpha_P, u_P and u_G belong to the same instant.
  if (coupling_->fluid) return coupling_->fluid->currentFraction();
  return parcelFraction();
}

std::vector<double> CfdDemSimulation::parcelFraction() const {
  if (coupling_->fluid) return coupling_->fluid->currentFraction(/*smoothed=*/false);
  const auto& map = coupling_->map();
  std::vector<coupling::KernelWeights> w;
  std::vector<double> volume;
  map.weightsOf(dem_->particles(), w);
  map.scatterVolume(dem_->particles(), w, volume);
  map.redistributeExcess(volume);
  return map.fractionOf(volume);
}

std::vector<Eigen::Vector3d> CfdDemSimulation::particleVelocity() const {
  const auto& map = coupling_->map();
  std::vector<coupling::KernelWeights> w;
  map.weightsOf(dem_->particles(), w);
  return map.meanVelocity(dem_->particles(), w);
}

std::vector<char> CfdDemSimulation::cellsHoldingParcels() const {
  const auto& map = coupling_->map();
  std::vector<coupling::KernelWeights> w;
  std::vector<double> volume;
  map.weightsOf(dem_->particles(), w);
  map.scatterVolume(dem_->particles(), w, volume);
  std::vector<char> holds(volume.size());
  for (std::size_t c = 0; c < volume.size(); ++c) holds[c] = volume[c] > 0.0;
  return holds;
}

coupling::VolumeMapping::VelocitySpread CfdDemSimulation::particleVelocitySpread() const {
  const auto& map = coupling_->map();
  std::vector<coupling::KernelWeights> w;
  map.weightsOf(dem_->particles(), w);
  return map.velocitySpread(dem_->particles(), w);
}

std::vector<Eigen::Vector3d> CfdDemSimulation::gasVelocity() const {
  if (gas_) return gas_->cellVelocity();
  return std::vector<Eigen::Vector3d>(std::size_t(grid_.cellCount()), Eigen::Vector3d::Zero());
}

double CfdDemSimulation::pressureDrop() const {
  if (!gas_) return 0.0;
  // The gas has gravity (buoyancy on the parcels): its own hydrostatic head between the inlet cells'
  // centres and the outlet, rho_G g (H - h/2), is not part of the bed's pressure drop.
  const double head = scene_.gas.density * dem_->settings().gravity.norm() *
                      (grid_.upperCorner().y() - grid_.origin.y() - 0.5 * grid_.spacing.y());
  return gas_->pressureDrop() - head;
}

void CfdDemSimulation::saveState(h5::File& file, const std::string& group) const {
  file.createGroup(group);
  dem_->saveState(file, group + "/dem");
  file.setAttribute(group, "dem_step", std::int64_t(demStep_));
  file.setAttribute(group, "has_gas", std::int64_t(gas_ ? 1 : 0));
  file.setAttribute(group, "last_interval", lastInterval_);
  if (gas_) {
    gas_->saveState(file, group + "/gas");
    file.write(group + "/alpha_p", coupling_->fluid->particleFraction());
  }
}

void CfdDemSimulation::loadState(const h5::File& file, const std::string& group) {
  if ((file.intAttribute(group, "has_gas") != 0) != (gas_ != nullptr))
    throw RunError("CFD-DEM checkpoint " + file.path() + ":" + group +
                   (gas_ ? " has no gas state, but the scene lists gas" : " has a gas state, but the scene has no gas"));
  dem_->loadState(file, group + "/dem");
  demStep_ = file.intAttribute(group, "dem_step");
  try {
    lastInterval_ = file.doubleAttribute(group, "last_interval");
  } catch (const RunError&) {
    lastInterval_ = 0.0;  // a checkpoint of an earlier version: the next step takes no dalpha/dt
  }
  if (gas_) {
    gas_->loadState(file, group + "/gas");
    coupling_->fluid->restoreFraction(file.readDoubles(group + "/alpha_p"));
  }
}

}  // namespace rcfd
