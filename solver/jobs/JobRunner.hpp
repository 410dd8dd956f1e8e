#pragma once
/// \file JobRunner.hpp
/// Job kinds ("database", "calibration", "spray") are runners registered by name; the job schema's
/// `kind` enum names the same kinds (jobKinds() in SceneLoader.hpp, what the server offers; a test holds
/// the two together). A runner reads its
/// inputs, writes DIR/summary.json and DIR/result.h5 (and its own artifacts), checkpoints into DIR so
/// that running the same job with the same DIR again resumes, and reports progress.

#include <nlohmann/json.hpp>
#include <string>

#include "core/Registry.hpp"
#include "scene/SceneLoader.hpp"

namespace rcfd {

struct RunOptions {
  std::string outDir;          ///< where summary.json, result.h5 and checkpoint.h5 go
  bool progressJson = false;   ///< JSON progress lines on stdout
  double progressInterval = 1.0;  ///< [s] of wall time between progress reports
  long stopAfterSteps = -1;    ///< testing: behave as if cancelled after this many steps (-1: never)
  /// testing: at most this many pressure-solver iterations per gas step of a database job (0: the gas
  /// solver's own limit), to make a gas solve fail as one that does not converge would
  int maxPressureIterations = 0;
};

class JobRunner {
 public:
  virtual ~JobRunner() = default;
  /// Runs the job; returns the summary written to summary.json. Throws InputError, RunError or
  /// Cancelled (after writing a checkpoint where the phase it stopped in has one).
  virtual nlohmann::json run(const JobSpec& job, const RunOptions& options) = 0;
};

using JobRunnerRegistry = Registry<JobRunner>;

/// Runs a job with the registered runner of its kind; writes summary.json atomically.
nlohmann::json runJob(const JobSpec& job, const RunOptions& options);

/// Writes text to path through a temporary file and a rename (readers never see half a file).
void writeFileAtomically(const std::string& path, const std::string& text);

}  // namespace rcfd
