#pragma once
/// \file TracerContext.hpp
/// What the stages of a tracer simulation share: the scene, geometry, database, the tracers and the
/// per-step recurrence state. Fields that only some effects need (tracer counts per cell, the tracer
/// volume fraction) start empty and are allocated by the effect that provides them, so a scene that
/// does not ask for them pays no memory.

#include <cstdint>
#include <memory>
#include <vector>

#include "fields/FieldDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "scene/Scene.hpp"
#include "tracers/FrameSampler.hpp"
#include "tracers/StepField.hpp"
#include "tracers/TracerCloud.hpp"

namespace rcfd {

/// Loops shorter than this run on one thread: a parallel region costs a few microseconds of fork and
/// barrier, more than a short loop's work (and spinning threads hurt most on a loaded machine).
inline constexpr std::int64_t kParallelThreshold = 4096;

struct SprayState;  // solver/spray/SprayState.hpp: parcels, balances, droplets per tracer

struct TracerContext {
  TracerContext(const Scene& scene, const Apparatus& apparatus, const FieldDatabase* database,
                const CartesianGrid& grid, TracerCloud& cloud, std::uint64_t seed)
      : scene(scene), apparatus(apparatus), database(database), grid(grid), cloud(cloud), seed(seed) {}

  const Scene& scene;
  const Apparatus& apparatus;
  /// The database the frames come from; null when the stages run on frames from elsewhere (the
  /// database job's reference coverage runs the spray effects on the CFD-DEM's own fields).
  const FieldDatabase* database;
  const CartesianGrid& grid;
  TracerCloud& cloud;
  std::uint64_t seed = 1;

  std::vector<double> openVolume;  ///< open volume of each cell [m3]
  /// Per cell, the plate faces trilinear sampling does not cross (plateFacesAbove,
  /// geometry/ThinWalls.hpp); empty without plates. Set by TracerSimulation.
  std::vector<std::uint8_t> plateFaces;
  const std::uint8_t* plateFacesOrNull() const { return plateFaces.empty() ? nullptr : plateFaces.data(); }
  double dt = 0.0;                 ///< tracer time step [s]
  std::int64_t step = 0;           ///< index of the step being taken (time = step * dt)
  std::int64_t discardSteps = 0;   ///< statistics ignore steps before this one (calibration)
  std::int64_t totalSteps = 0;     ///< planned length of the run

  // Recurrence state of the current step (set before the stages run).
  std::shared_ptr<const FieldFrame> frame;      ///< frame of this step
  std::shared_ptr<const FieldFrame> nextFrame;  ///< next frame of the same sequence, when blending
  double blend = 0.0;                           ///< weight of nextFrame in [0, 1)
  FrameSampler sampler() const { return FrameSampler(grid, frame.get(), nextFrame.get(), blend, plateFacesOrNull()); }
  /// u_P^rec or u_G^rec of this step as a step field (built on first use in the step).
  const StepVelocityField& stepVelocity(bool useGas, StepFieldLayout layout = StepFieldLayout::Padded) {
    return stepFields.velocity(sampler(), useGas, grid.cellCount() > kParallelThreshold, layout);
  }
  StepFields stepFields;  ///< invalidated whenever frame, nextFrame or blend change

  // Provided by `tracer_volume_fraction` (empty otherwise).
  std::vector<std::int32_t> tracerCell;   ///< cell of every tracer at the start of the step
  std::vector<std::int32_t> tracerCount;  ///< tracers per cell at the start of the step
  std::vector<float> tracerAlpha;         ///< alpha_P of the tracers per cell [-]
  /// The cells of the positions the motion kernel wrote, for the next step's tracerCell (the kernel
  /// finds them while the positions are in cache; re-reading every position costs more). Valid only
  /// when nextTracerCellStep == step; anything else that moves tracers must set it to -1
  /// (TracerSimulation::context() does, for whoever takes the context to change the cloud).
  std::vector<std::int32_t> nextTracerCell;
  std::int64_t nextTracerCellStep = -1;

  // Provided by `velocity_streams` (empty otherwise): per tracer index, the velocity of the tracer's
  // stream relative to u_P^rec, u_stream - u_P^rec of its cell [m/s] (x, y, z arrays), which the motion
  // kernel adds to Eq. (9) over the step.
  std::vector<float> streamVelocity[3];

  // Provided by `spray` (null otherwise); `deposition` adds per-cell and per-tracer arrays to it.
  std::shared_ptr<SprayState> spray;

  double time() const { return double(step) * dt; }
  bool collecting() const { return step >= discardSteps; }
};

}  // namespace rcfd
