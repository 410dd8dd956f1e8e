// Two-way coupling of DEM and gas: mapping, drag, exchange, fluid forces (FluidCoupling.hpp).

#include "cfddem/coupling/FluidCoupling.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/Errors.hpp"

namespace rcfd::coupling {

/// Below this alpha_G a cell is treated as a failure of the over-packing treatment, not as physics.
constexpr double kMinGasFraction = 0.2;

FluidCoupling::FluidCoupling(const Scene& scene, gas::GasSolver& gas, DemSystem& dem, FluidCouplingOptions options)
    : scene_(scene), gas_(gas), dem_(dem), options_(std::move(options)) {
  model_ = DragModelRegistry::createAt("scene", "/gas/drag_model", scene_.gas.drag_model, scene_);
  mapping_ = std::make_unique<VolumeMapping>(gas_.grid(), gas_.openFraction(), gas_.activeCells(),
                                             gas_.apertures().baffles);
  if (options_.smoothingLength > 0)
    smoother_ = std::make_unique<FieldSmoother>(*mapping_, gas_.faceKinds(0), gas_.faceKinds(1), gas_.faceKinds(2),
                                                options_.smoothingLength);
  const std::size_t cells = std::size_t(gas_.grid().cellCount());
  alphaP_.assign(cells, 0.0);
  alphaG_.assign(cells, 1.0);
  beta_.assign(cells, 0.0);
  uP_.assign(cells, Eigen::Vector3d::Zero());
}

std::vector<Eigen::Vector3d> FluidCoupling::gasVelocitySeen() const {
  std::vector<Eigen::Vector3d> u = gas_.cellVelocity();
  if (smoother_) smoother_->smooth(u);  // the adjoint of smoothing the exchange fields
  return u;
}

std::vector<double> FluidCoupling::currentFraction(bool smoothed) const {
  std::vector<KernelWeights> w;
  std::vector<double> volume;
  mapping_->weightsOf(dem_.particles(), w);
  mapping_->scatterVolume(dem_.particles(), w, volume);
  if (smoother_ && smoothed) {
    std::vector<double> a = mapping_->fractionOf(volume);
    smoother_->smooth(a);
    for (std::size_t c = 0; c < a.size(); ++c) volume[c] = a[c] * mapping_->openVolume(c);
  }
  mapping_->redistributeExcess(volume, options_.maxParticleFraction);
  return mapping_->fractionOf(volume);
}

void FluidCoupling::prepare(double interval) {
  const DemParticles& p = dem_.particles();
  const std::size_t n = p.size(), cells = alphaP_.size();
  const long lc = long(cells), ln = long(n);
  const bool parallelCells = lc >= kParallelCells;
  mapping_->weightsOf(p, weights_);
  // The scatters below gather per cell in parcel order: the serial scatter's sums on any thread count.
  mapping_->contributionsOf(weights_, contributions_);
  mapping_->gatherVolume(p, contributions_, volume_);
  // The drag closure sees the parcel's own surroundings: the mapped (unsmoothed) packing, with the
  // over-packing redistribution. Smoothing is a device for the gas equations (Eq. 3, "to ensure
  // stability"); a smoothed packing in F(eps, Re), which is convex in alpha_P, would take drag away
  // from every parcel near the edge of a dense region (docs/physics.md).
  localVolume_ = volume_;
  mapping_->redistributeExcess(localVolume_, options_.maxParticleFraction);
  localAlphaG_ = mapping_->fractionOf(localVolume_);
#pragma omp parallel for schedule(static) if (parallelCells)
  for (long c = 0; c < lc; ++c) localAlphaG_[std::size_t(c)] = 1.0 - localAlphaG_[std::size_t(c)];
  if (smoother_) {
#pragma omp parallel for schedule(static) if (parallelCells)
    for (long lcell = 0; lcell < lc; ++lcell) {
      const std::size_t c = std::size_t(lcell);
      alphaP_[c] = mapping_->usable()[c] ? volume_[c] / mapping_->openVolume(c) : 0.0;
    }
    smoother_->smooth(alphaP_);
#pragma omp parallel for schedule(static) if (parallelCells)
    for (long c = 0; c < lc; ++c)
      volume_[std::size_t(c)] = alphaP_[std::size_t(c)] * mapping_->openVolume(std::size_t(c));
  }
  redistributed_ = mapping_->redistributeExcess(volume_, options_.maxParticleFraction);
  alphaP_ = mapping_->fractionOf(volume_);
  long firstTooDense = lc;
#pragma omp parallel for schedule(static) reduction(min : firstTooDense) if (parallelCells)
  for (long lcell = 0; lcell < lc; ++lcell) {
    const std::size_t c = std::size_t(lcell);
    alphaG_[c] = mapping_->usable()[c] ? 1.0 - alphaP_[c] : 1.0;
    if (!(alphaG_[c] >= kMinGasFraction)) firstTooDense = std::min(firstTooDense, lcell);
  }
  if (firstTooDense < lc) {
    const std::size_t c = std::size_t(firstTooDense);
    const auto ijk = gas_.grid().cellIjk(std::int64_t(c));
    std::ostringstream s;
    s << "coupling: alpha_P = " << alphaP_[c] << " in cell (" << ijk[0] << ", " << ijk[1] << ", " << ijk[2]
      << ") at t = " << dem_.time() << " s after the over-packing redistribution (limit "
      << options_.maxParticleFraction << "): the cell has no open neighbour to take the excess";
    throw RunError(s.str());
  }
  // dalpha_G/dt as a backward difference over the interval in which the parcels moved (the previous
  // coupling step), not over the coming gas step: the two differ whenever a step is cut short (to hit
  // a sampling instant) and the gas would see the change at the wrong rate (pressure spikes).
  std::vector<double> rate(cells, 0.0);
  if (!first_ && interval > 0) {
#pragma omp parallel for schedule(static) if (parallelCells)
    for (long c = 0; c < lc; ++c)
      rate[std::size_t(c)] = (alphaG_[std::size_t(c)] - gas_.gasFractionOf(std::size_t(c))) / interval;
  }
  gas_.setGasFraction(alphaG_, rate);
  first_ = false;

  k_.assign(n, 0.0);
  std::fill(beta_.begin(), beta_.end(), 0.0);
  std::fill(uP_.begin(), uP_.end(), Eigen::Vector3d::Zero());
  if (options_.drag) {
    // The gas has not changed since the last applyForces(): its (smoothed) velocity is reused.
    if (!seenValid_) uSeen_ = gasVelocitySeen();
    const std::vector<Eigen::Vector3d>& u = uSeen_;
    const double cg = scene_.dem.coarse_graining, d = scene_.particles.diameter;
    const double nu = scene_.gas.kinematic_viscosity, mu = scene_.gas.density * nu;
    const double stokes = cg * cg * cg * 3.0 * std::numbers::pi * mu * d;
#pragma omp parallel for schedule(static) if (ln >= kParallelParcels)
    for (long li = 0; li < ln; ++li) {
      const std::size_t i = std::size_t(li);
      const double eps = VolumeMapping::interpolate(localAlphaG_, weights_[i]);
      const Eigen::Vector3d slip = VolumeMapping::interpolate(u, weights_[i]) - p.v[i];
      const double re = d * eps * slip.norm() / nu;
      k_[i] = stokes * eps * model_->normalisedDrag(eps, re);  // K_i [kg/s]
    }
    // (beta, beta u_P) per cell in one array: gathered in parcel order, smoothed, split.
    std::vector<Eigen::Vector4d> bk(cells);
    const CellContributions& e = contributions_;
#pragma omp parallel for schedule(static) if (parallelCells)
    for (long lcell = 0; lcell < lc; ++lcell) {
      const std::size_t c = std::size_t(lcell);
      Eigen::Vector4d sum = Eigen::Vector4d::Zero();
      for (std::int32_t q = e.start[c]; q < e.start[c + 1]; ++q) {
        const std::size_t i = std::size_t(e.parcel[std::size_t(q)]);
        const double wk = e.weight[std::size_t(q)] * k_[i];
        sum += wk * Eigen::Vector4d(1.0, p.v[i].x(), p.v[i].y(), p.v[i].z());
      }
      bk[c] = mapping_->usable()[c] ? Eigen::Vector4d(sum / mapping_->openVolume(c)) : sum;
    }
    if (smoother_) smoother_->smooth(bk);
#pragma omp parallel for schedule(static) if (parallelCells)
    for (long lcell = 0; lcell < lc; ++lcell) {
      const std::size_t c = std::size_t(lcell);
      beta_[c] = bk[c][0];
      uP_[c] = beta_[c] > 0 ? Eigen::Vector3d(bk[c].tail<3>() / beta_[c]) : Eigen::Vector3d::Zero();
    }
  }
  gas_.setDragSource(beta_, uP_);
  seenValid_ = false;  // the gas steps next
}

void FluidCoupling::applyForces() {
  DemParticles& p = dem_.particles();
  const std::size_t n = p.size();
  if (weights_.size() != n) throw RunError("coupling: applyForces() without prepare() for the current parcels");
  drag_.assign(n, Eigen::Vector3d::Zero());
  if (options_.drag) uSeen_ = gasVelocitySeen();
  seenValid_ = options_.drag;
  const std::vector<Eigen::Vector3d>& u = uSeen_;
  const long ln = long(n);
#pragma omp parallel for schedule(static) if (ln >= kParallelParcels)
  for (long li = 0; li < ln; ++li) {
    const std::size_t i = std::size_t(li);
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    if (options_.drag) {
      drag_[i] = k_[i] * (VolumeMapping::interpolate(u, weights_[i]) - p.v[i]);
      f += drag_[i];
    }
    if (options_.pressureForce) f -= parcelVolume(p, i) * gas_.pressureGradientAt(p.x[i]);
    p.fluid_force[i] = f;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!p.fluid_force[i].allFinite()) {
      std::ostringstream s;
      s << "coupling: the fluid force on parcel " << p.id[i] << " at (" << p.x[i].transpose() << ") m is not finite at t = "
        << dem_.time() << " s";
      throw RunError(s.str());
    }
}

Eigen::Vector3d FluidCoupling::particleDragSum() const {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& f : drag_) s += f;
  return s;
}

Eigen::Vector3d FluidCoupling::gasDragSum() const {
  const std::vector<Eigen::Vector3d> u = gas_.cellVelocity();
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (std::size_t c = 0; c < beta_.size(); ++c)
    if (beta_[c] > 0) s += mapping_->openVolume(c) * beta_[c] * (uP_[c] - u[c]);
  return s;
}

void FluidCoupling::restoreFraction(std::vector<double> alphaP) {
  if (alphaP.size() != alphaP_.size()) throw RunError("coupling checkpoint: alpha_P does not match the grid");
  alphaP_ = std::move(alphaP);
  first_ = false;  // the gas state of the checkpoint has this alpha_G already
  for (std::size_t c = 0; c < alphaP_.size(); ++c) alphaG_[c] = mapping_->usable()[c] ? 1.0 - alphaP_[c] : 1.0;
}

double FluidCoupling::maxParticleFraction() const {
  return alphaP_.empty() ? 0.0 : *std::max_element(alphaP_.begin(), alphaP_.end());
}

}  // namespace rcfd::coupling
