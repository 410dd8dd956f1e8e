#pragma once
/// \file CfdDemSimulation.hpp
/// The built-in coarse-grained CFD-DEM of a scene: the DEM (DemSystem), the gas phase (gas::GasSolver,
/// only when the scene lists the effect `gas`) and their coupling (particle volume mapped to the grid,
/// optional smoothing by Eq. (3), Beetstra drag and the pressure-gradient force, momentum exchange
/// back to the gas). One coupling step is one gas step of a whole number of DEM steps, so simulated
/// time is an integer count of DEM steps and never drifts.
///
/// This is the interface the database job (jobs/DatabaseJob.cpp) drives; the coupling itself lives in
/// cfddem/coupling/. Fields are per grid cell in the field database's order (x fastest).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cfddem/DemFilling.hpp"
#include "cfddem/DemSystem.hpp"
#include "cfddem/coupling/VolumeMapping.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/CartesianGrid.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

namespace h5 {
class File;
}
namespace gas {
class GasSolver;
struct GasOptions;
}
namespace coupling {
class FluidCoupling;
}

/// Figures of the last coupling step.
struct CfdDemStepStats {
  double dt = 0.0;          ///< gas step = demSteps * dt_DEM [s]
  int demSteps = 0;         ///< DEM sub-steps in this coupling step
  int pressureIterations = 0;
  double courant = 0.0;     ///< gas Courant number after the step [-]
  double maxAlphaP = 0.0;   ///< largest particle volume fraction of a cell [-]
};

class CfdDemSimulation {
 public:
  /// Builds apparatus, grid, DEM (walls, contact and rolling models of the scene) and, when the scene
  /// lists `gas`, the gas solver and coupling (`drag`, `smoothing` select their stages). Throws
  /// InputError naming the scene field on an inconsistent set-up.
  CfdDemSimulation(const Scene& scene, std::uint64_t seed);
  /// The same with gas-solver options that are not in the scene (verification set-ups: a box with a
  /// bottom inlet, slip walls). The gas gravity is always the DEM's.
  CfdDemSimulation(const Scene& scene, std::uint64_t seed, const gas::GasOptions& gasOptions);
  ~CfdDemSimulation();

  /// Inserts the scene's bed mass as parcels and lets it settle (DEM only, gas off), at most
  /// scene.dem.settle_time. Deterministic for the seed. `stopRequested`, `stageStarted` and `progress`
  /// as FillOptions::stop_requested, FillOptions::stage_started and FillOptions::progress.
  FillResult fillAndSettle(const std::function<bool()>& stopRequested = {},
                           const std::function<void(FillStage)>& stageStarted = {},
                           const std::function<void(FillStage, double)>& progress = {});
  /// DEM steps each batch of fillAndSettle() falls (fallStepsPerBatch() of the scene's fill region).
  long fillFallSteps() const;

  /// Scales the inlet and nozzle flows by factor in [0, 1] (the database job ramps the gas up).
  void setFlowFactor(double factor);

  /// Advances by one coupling step: at most scene.dem.coupling_interval DEM steps, fewer when the gas
  /// CFL limit asks for it, and never past `untilDemStep` (so sampling instants are hit exactly).
  /// Without `gas` it runs DEM steps only. Throws RunError on a non-finite state.
  const CfdDemStepStats& step(std::int64_t untilDemStep);

  std::int64_t demStep() const;   ///< DEM steps since construction (the clock)
  double time() const;            ///< demStep() * dt_DEM [s]
  double demTimeStep() const;

  const Scene& scene() const { return scene_; }
  const Apparatus& apparatus() const { return *apparatus_; }
  const CartesianGrid& grid() const { return grid_; }
  const DemSystem& dem() const { return *dem_; }
  DemSystem& dem() { return *dem_; }
  bool hasGas() const { return gas_ != nullptr; }
  const gas::GasSolver* gasSolver() const { return gas_.get(); }

  /// alpha_P per cell of the current parcels, processed as the coupling does (smoothing when enabled,
  /// over-packing redistribution) [-]: the same instant as particleVelocity() and gasVelocity().
  std::vector<double> particleFraction() const;
  /// alpha_P per cell of the current parcels' own kernel volume, over-packing redistributed as the
  /// coupling does but not smoothed [-]: the field particleVelocity() is the velocity of, so that
  /// alpha_P u_P is the parcels' volume flux (with smoothing off, particleFraction() itself).
  std::vector<double> parcelFraction() const;
  /// Volume-weighted mean parcel velocity per cell, zero where a cell holds no particle volume [m/s].
  std::vector<Eigen::Vector3d> particleVelocity() const;
  /// 1 for the cells a parcel maps volume to (before smoothing): those particleVelocity() is the
  /// velocity of; a cell with alpha_P > 0 and 0 here got its volume from the smoothing alone.
  std::vector<char> cellsHoldingParcels() const;
  /// The velocity spread of the same instant (VolumeMapping::velocitySpread): up share, the mean velocity
  /// of the up- and down-moving volume, the variance per component.
  coupling::VolumeMapping::VelocitySpread particleVelocitySpread() const;
  /// Gas velocity at cell centres, zero in closed cells and without gas [m/s].
  std::vector<Eigen::Vector3d> gasVelocity() const;
  /// Bed pressure drop: inlet minus outlet pressure [Pa], less the gas's own hydrostatic head
  /// rho_G g (H - h/2) (the gas has gravity); 0 without gas.
  double pressureDrop() const;

  /// Whole state (particles, contact history where kept, gas, clock) into / from a checkpoint group.
  void saveState(h5::File& file, const std::string& group) const;
  void loadState(const h5::File& file, const std::string& group);

  const CfdDemStepStats& lastStep() const { return last_; }
  /// The coupling (mapping, drag, exchange sums); null without `gas`.
  const coupling::FluidCoupling* fluidCoupling() const;

 private:
  struct Coupling;  // volume mapping, drag, exchange (cfddem/coupling/)
  /// RunError naming the first parcel with a non-finite position or velocity; InputError naming
  /// /dem/time_step for a parcel outside the chamber's bounding box (a DEM step too long for its speed).
  void checkParcels() const;

  const Scene& scene_;
  std::uint64_t seed_;
  std::unique_ptr<Apparatus> apparatus_;
  CartesianGrid grid_;
  std::unique_ptr<DemSystem> dem_;
  std::unique_ptr<gas::GasSolver> gas_;
  std::unique_ptr<Coupling> coupling_;
  CfdDemStepStats last_;
  std::int64_t demStep_ = 0;
  double lastInterval_ = 0.0;  ///< duration of the last coupling step [s] (dalpha_G/dt of the next)
};

}  // namespace rcfd
