#pragma once
/// \file FluidCoupling.hpp
/// The two-way coupling of the DEM and the gas, model A of the paper (Eq. 1-2) in a semi-implicit
/// form. Per coupling step:
///   1. before the gas step (prepare): kernel weights of every parcel (VolumeMapping), particle volume
///      per cell, optional Eq. (3) smoothing, over-packing redistribution -> alpha_P, alpha_G = 1 -
///      alpha_P; per parcel the drag coefficient K_i = cg^3 3 pi mu d eps F(eps, Re) from the current
///      gas (eps and u_G interpolated with the same weights); per cell beta = sum_i w_ic K_i / (V phi)
///      and the K-weighted parcel velocity (smoothed like alpha_P) -> GasSolver (implicit drag).
///   2. after the gas step (applyForces): force on parcel i, K_i (u_G(x_i) - v_i) - V_i grad p(x_i),
///      with the new gas velocity; the DEM keeps it for the coupling step's sub-steps.
/// The drag a parcel takes from a cell is what the cell's gas loses, so the total drag on the parcels
/// equals minus the total drag on the gas to round-off (particleDragSum, gasDragSum).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "cfddem/DemSystem.hpp"
#include "cfddem/coupling/DragModel.hpp"
#include "cfddem/coupling/FieldSmoother.hpp"
#include "cfddem/coupling/VolumeMapping.hpp"
#include "cfddem/gas/GasSolver.hpp"

namespace rcfd::coupling {

struct FluidCouplingOptions {
  bool drag = true;            ///< effect `drag`: drag and the exchange to the gas; else none
  bool pressureForce = true;   ///< -V_p grad p on the parcels (model A)
  double smoothingLength = 0;  ///< effect `smoothing`: Eq. (3) with this L_smooth [m]; 0 off
  double maxParticleFraction = kMaxParticleFraction;
};

class FluidCoupling {
 public:
  FluidCoupling(const Scene& scene, gas::GasSolver& gas, DemSystem& dem, FluidCouplingOptions options);

  /// Step 1: maps the particles, hands alpha_G and the drag to the gas. dalpha_G/dt is the change since
  /// the last prepare() over `interval`, the time the parcels moved since then [s] (0: no rate, e.g. at
  /// the start). Throws RunError when a cell stays over-packed or a value is not finite.
  void prepare(double interval = 0.0);
  /// Step 2: fluid forces on the parcels from the gas state after its step.
  void applyForces();

  /// True once prepare() ran (or a checkpoint was restored): particleFraction() is the coupling's.
  bool prepared() const { return !first_; }
  /// alpha_P of the current parcels, processed as prepare() does (smoothing when `smoothed` and
  /// enabled, redistribution), without touching the gas [-].
  std::vector<double> currentFraction(bool smoothed = true) const;
  /// alpha_P per cell after smoothing and redistribution [-].
  const std::vector<double>& particleFraction() const { return alphaP_; }
  const std::vector<double>& gasFraction() const { return alphaG_; }
  /// Drag coefficient per unit open volume handed to the gas, beta [kg/(m3 s)].
  const std::vector<double>& beta() const { return beta_; }
  /// Sum of the drag forces on the parcels of the last applyForces() [N].
  Eigen::Vector3d particleDragSum() const;
  /// Sum over cells of V phi beta (u_P - u_G) with the gas velocity after its step: the drag force the
  /// gas receives through the exchange fields [N] (call after the gas step).
  Eigen::Vector3d gasDragSum() const;
  /// Cells that gave volume in the last over-packing redistribution.
  long redistributedCells() const { return redistributed_; }
  double maxParticleFraction() const;
  const VolumeMapping& mapping() const { return *mapping_; }
  const std::vector<KernelWeights>& weights() const { return weights_; }
  /// Restores alpha_P (and alpha_G) of a checkpoint, so particleFraction() is what it was at the save.
  void restoreFraction(std::vector<double> alphaP);
  /// Drag force on each parcel of the last applyForces() [N] (index order).
  const std::vector<Eigen::Vector3d>& dragForces() const { return drag_; }
  /// The drag law F(eps, Re), the scene's gas.drag_model.
  const DragModel& dragModel() const { return *model_; }

 private:
  std::vector<Eigen::Vector3d> gasVelocitySeen() const;

  const Scene& scene_;
  gas::GasSolver& gas_;
  DemSystem& dem_;
  FluidCouplingOptions options_;
  std::unique_ptr<DragModel> model_;
  std::unique_ptr<VolumeMapping> mapping_;
  std::unique_ptr<FieldSmoother> smoother_;
  std::vector<KernelWeights> weights_;
  CellContributions contributions_;  ///< weights_ by cell (the deterministic parallel scatters)
  std::vector<double> volume_, alphaP_, alphaG_, beta_, k_;
  std::vector<double> localVolume_, localAlphaG_;  ///< unsmoothed packing for the drag closure
  std::vector<Eigen::Vector3d> uP_, drag_;
  long redistributed_ = 0;
  /// The first prepare() finds the gas at alpha_G = 1 although the bed was there all along (settled
  /// with the gas off): it sets alpha_G without a rate, so no spurious expulsion flow.
  bool first_ = true;
  /// Gas velocity at cell centres as the parcels see it (smoothed with smoothing), valid from
  /// applyForces() until the gas steps again.
  std::vector<Eigen::Vector3d> uSeen_;
  bool seenValid_ = false;
};

}  // namespace rcfd::coupling
