#pragma once
/// \file TracerSimulation.hpp
/// The Lagrangian rCFD loop: tracers stepped through the recurrence fields along a recurrence path, with
/// exactly the effects the scene lists. Time is an integer step count (t = step * dt), so a 1 h run of
/// 720,000 steps does not drift, and a checkpoint restores the run bit for bit.

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "recurrence/RecurrencePath.hpp"
#include "tracers/MotionKernel.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {

struct TracerRunSettings {
  std::uint64_t seed = 1;
  std::int64_t steps = 0;         ///< planned number of steps
  std::int64_t discardSteps = 0;  ///< statistics start at this step
  bool vectorisedKernel = true;   ///< false: the motion kernel's scalar path for every tracer (tests)
  /// The tracers are sorted by cell at the steps that are multiples of this (0: never). Sorted tracers
  /// read the step fields from cache (neighbours in memory share corners); the order decays as they
  /// mix. A fixed interval keeps results a function of the scene and seed.
  std::int64_t sortInterval = 100;
};

class TracerSimulation {
 public:
  /// Builds the stages the scene asks for (InputError for unknown effects or missing dependencies, or
  /// a dt that is not dt_rec divided by a whole number) and places the tracers in proportion to
  /// alpha_P^rec x open volume of the path's first frame.
  TracerSimulation(const Scene& scene, std::shared_ptr<const FieldDatabase> database, RecurrencePath path,
                   const TracerRunSettings& settings);
  ~TracerSimulation();

  void step();
  std::int64_t currentStep() const { return context_->step; }
  double time() const { return context_->time(); }
  double dt() const { return context_->dt; }
  const TracerRunSettings& settings() const { return settings_; }

  const TracerCloud& cloud() const { return cloud_; }
  /// Mutable access (tests and benchmarks move tracers with it): forgets the motion kernel's tracer
  /// cells, which tracer_volume_fraction then recomputes from the positions.
  TracerContext& context() {
    context_->nextTracerCellStep = -1;
    return *context_;
  }
  const TracerContext& context() const { return *context_; }
  const MotionStatistics& motionStatistics() const { return kernel_->statistics(); }
  /// Names of the effects that were built, in execution order.
  const std::vector<std::string>& effectNames() const { return effectNames_; }
  const TracerEffect* effect(const std::string& name) const;
  /// Bytes allocated by each effect (0 for an effect not built: it does not exist).
  std::size_t allocatedBytes(const std::string& effect) const;

  /// Reorders the tracers by cell (stable: by index within a cell), with every effect's per-tracer
  /// state, and hands the cells to tracer_volume_fraction. step() calls it at every multiple of
  /// settings().sortInterval.
  void sortTracers();

  void saveCheckpoint(const std::string& path) const;
  void loadCheckpoint(const std::string& path);
  /// Writes result.h5 content and fills the summary with every effect's figures.
  void writeResults(h5::File& out, nlohmann::json& summary) const;
  /// Writes every effect's SVG figures into outDir; returns the file names.
  std::vector<std::string> writeFigures(const std::string& outDir) const;

  /// Wall seconds spent in each stage since construction (or resetStageSeconds()): every built
  /// effect's beforeMove + afterMove under its name, "motion" for the kernel's move, "frames" for
  /// loading the next step's frames, "sort" for sortTracers(). What each effect costs, measured inside one run (the benchmark).
  std::vector<std::pair<std::string, double>> stageSeconds() const;
  void resetStageSeconds();

  /// Frame used at `step` and, when dt < dt_rec, the blending partner and weight.
  void frameAt(std::int64_t step, int& frame, int& next, double& blend) const;

 private:
  void placeTracers();
  void loadFrames();

  Scene scene_;
  std::shared_ptr<const FieldDatabase> database_;
  RecurrencePath path_;
  TracerRunSettings settings_;
  std::unique_ptr<Apparatus> apparatus_;
  TracerCloud cloud_;
  std::unique_ptr<TracerContext> context_;
  std::vector<std::string> effectNames_;
  std::vector<std::unique_ptr<TracerEffect>> effects_;
  std::unique_ptr<MotionKernel> kernel_;
  int stepsPerFrame_ = 1;
  bool linearBetweenFrames_ = false;  ///< scene rcfd.frame_interpolation "linear"
  std::vector<double> effectSeconds_;  ///< per effect, in effects_' order
  double motionSeconds_ = 0.0, frameSeconds_ = 0.0, sortSeconds_ = 0.0;
  bool keepsVelocities_ = false;  ///< free_flight: the cloud's velocities are state
  struct SortScratch {
    std::vector<std::int32_t> cell, from, ints;
    std::vector<std::int64_t> start;
    std::vector<double> doubles;
  } sortScratch_;
};

}  // namespace rcfd
