#pragma once
/// \file DatabaseSchedule.hpp
/// The database job's timetable in whole DEM steps after the bed has settled: the gas ramp
/// (dem.ramp_time), the warm-up at full flow (dem.warmup), then frames every dt_rec = 1/sample_rate for
/// sample_duration and reference-series samples every 1/probe_rate over the sampled and the reference
/// periods. Frames and samples fall exactly on DEM steps, so the rates must divide the DEM step.

#include <cstdint>
#include <vector>

#include "core/Errors.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

struct DatabaseSchedule {
  double dtDem = 0.0;               ///< dt_DEM [s]
  std::int64_t rampSteps = 0;       ///< DEM steps of the linear gas ramp
  std::int64_t warmupSteps = 0;     ///< DEM steps at full flow before frame 0
  std::int64_t frameSteps = 0;      ///< DEM steps per frame, dt_rec / dt_DEM
  std::int64_t sampleSteps = 0;     ///< DEM steps per reference sample, 1 / (probe_rate dt_DEM)
  std::int64_t frames = 0;          ///< sample_duration * sample_rate
  std::int64_t referenceSamples = 0;  ///< reference_duration * probe_rate

  /// Validates the scene's dem section against these rules; rcfd::InputError naming each offending
  /// field (/dem/sample_rate, /dem/probe_rate, /dem/sample_duration, /dem/reference_duration) and what
  /// is allowed.
  static DatabaseSchedule fromScene(const Scene& scene);
  /// The same rules as violations (empty when the scene has a schedule): what a database job is
  /// refused for when it is submitted (checkDatabaseScene).
  static std::vector<Violation> violations(const Scene& scene);

  double dtRec() const { return double(frameSteps) * dtDem; }
  double sampleDt() const { return double(sampleSteps) * dtDem; }
  std::int64_t samplesPerFrame() const { return frameSteps / sampleSteps; }
  /// Reference samples during the sampled period (one frame interval each covers samplesPerFrame()).
  std::int64_t sampledSamples() const { return frames * samplesPerFrame(); }
  std::int64_t totalSamples() const { return sampledSamples() + referenceSamples; }
  /// DEM steps after settling to frame k and to sample s.
  std::int64_t frameOffset(std::int64_t k) const { return rampSteps + warmupSteps + k * frameSteps; }
  std::int64_t sampleOffset(std::int64_t s) const { return rampSteps + warmupSteps + s * sampleSteps; }
  /// DEM steps after settling to the last frame or sample: the end of the job.
  std::int64_t endOffset() const;
  /// Gas flow factor in [0, 1] after `offset` DEM steps since settling: linear over the ramp.
  double flowFactor(std::int64_t offset) const;

 private:
  static DatabaseSchedule schedule(const Scene& scene, std::vector<Violation>& out);
};

}  // namespace rcfd
