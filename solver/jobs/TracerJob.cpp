// The "spray" job: a tracer simulation with the scene's effects on an existing database, for
// `duration` simulated seconds, with checkpoints, resume and progress. (Spray deposition itself plugs in
// as further effects.)
//
// Cancellation (jobs/Cancellation.hpp) by phase, as the progress names them: "recurrence" (reading the
// database, its recurrence matrix, the path) polls between frames and tiles and keeps nothing; "run"
// polls after every tracer step and checkpoints; "results" looks between its parts and checkpoints the
// finished run, so a resume only writes the results again.
#include <chrono>
#include <filesystem>
#include <spdlog/spdlog.h>

#include "analysis/CoverageComparison.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "analysis/StayComparison.hpp"
#include "core/Errors.hpp"
#include "jobs/Cancellation.hpp"
#include "jobs/JobRunner.hpp"
#include "jobs/Progress.hpp"
#include "jobs/RecurrenceSetup.hpp"
#include "spray/Coverage.hpp"
#include "tracers/TracerSimulation.hpp"

namespace rcfd {
namespace {

/// The run's spray-zone stays against the full simulation's reference in the database, on the tracers'
/// step lattice (analysis/StayComparison.hpp); null without residence_time or without a reference.
nlohmann::json stayComparison(const JobSpec& job, const Scene& scene, const std::string& resultPath,
                              std::int64_t steps) {
  analysis::ReferenceStatistics reference;
  try {
    reference = analysis::readReferenceStatistics(job.database);
  } catch (const InputError& e) {  // a damaged reference must not cost the finished run its summary
    spdlog::warn("no stay comparison: {}", e.what());
    return {{"error", e.what()}};
  }
  h5::File result(resultPath, h5::File::Mode::ReadOnly);
  const char* counts = "/residence_time/duration_steps_counts";
  if (!reference.hasDurations() || !result.exists(counts)) return nullptr;
  const double members = analysis::referenceMembers(reference, scene.process.bed_mass, scene.particles.density,
                                                    scene.particles.diameter);
  return analysis::compareStays(result.readInt64s(counts), scene.rcfd.dt, double(scene.rcfd.tracers),
                                double(steps) * scene.rcfd.dt, reference.durations, members,
                                reference.recordedPeriod())
      .toJson();
}

/// The run's coverage distribution against the full simulation's over the same duration
/// (analysis/CoverageComparison.hpp); null without coverage or without a reference coverage.
nlohmann::json coverageComparison(const JobSpec& job, const Scene& scene, const std::string& resultPath,
                                  double particlesPerTracer, double duration) {
  const char* droplets = "/coverage/droplets_per_particle";
  try {
    const auto reference = analysis::readReferenceCoverage(job.database);
    h5::File result(resultPath, h5::File::Mode::ReadOnly);
    if (!reference || !result.exists(droplets)) return nullptr;
    const double f = singleDropletCoverage(scene.spray.droplet_diameter, scene.particles.diameter);
    return analysis::compareCoverage(result.readDoubles(droplets), particlesPerTracer, duration, scene.rcfd.dt, f,
                                     *reference)
        .toJson();
  } catch (const InputError& e) {  // a damaged or foreign reference must not cost the finished run its summary
    spdlog::warn("no coverage comparison: {}", e.what());
    return {{"error", e.what()}};
  }
}

class TracerJob final : public JobRunner {
 public:
  nlohmann::json run(const JobSpec& job, const RunOptions& options) override {
    const Scene& scene = job.scene;
    if (job.database.empty()) throw InputError("job", "/database", "a spray job needs a database");
    const auto wallStart = std::chrono::steady_clock::now();
    requireJobRules(job);
    const std::int64_t steps = std::llround(job.duration / scene.rcfd.dt);

    const std::string checkpoint = options.outDir + "/checkpoint.h5";
    double priorWall = 0.0;
    if (std::filesystem::exists(checkpoint)) {
      h5::File f(checkpoint, h5::File::Mode::ReadOnly);
      if (f.exists("/state/wall_time")) priorWall = f.readDoubles("/state/wall_time").at(0);
    }
    ProgressReporter progress(options.progressJson, options.progressInterval);
    progress.setPriorWallTime(priorWall);
    progress.setPhase("recurrence");
    progress.report(0.0, 0.0, true);

    // The path is indexed per frame; dt may divide dt_rec, so size it for the number of frames used.
    RecurrenceSetup rec =
        prepareRecurrence(scene, job.database, steps + 2, job.seed, [] { return cancellationRequested(); });
    TracerRunSettings settings{job.seed, steps, 0};
    TracerSimulation sim(scene, rec.database, rec.path, settings);
    if (std::filesystem::exists(checkpoint)) {
      sim.loadCheckpoint(checkpoint);
      spdlog::info("resumed from {} at step {} of {}", checkpoint, sim.currentStep(), steps);
    }
    const std::int64_t checkpointEvery =
        std::max<std::int64_t>(1, std::llround(job.checkpoint_interval / scene.rcfd.dt));

    progress.setStartFraction(double(sim.currentStep()) / double(steps));
    progress.setPhase("run");
    progress.report(double(sim.currentStep()) / double(steps), sim.time(), true);
    auto save = [&] {
      // The wall time goes into the checkpoint in place: a forced exit must not cut either write.
      const ForcedExitDeferral keepTheCheckpoint;
      sim.saveCheckpoint(checkpoint);
      h5::File f(checkpoint, h5::File::Mode::ReadWrite);
      f.write("/state/wall_time", std::vector<double>{priorWall + progress.wallTime()});
    };
    auto cancelled = [&](const std::string& where) {
      save();
      throw Cancelled("stopped " + where + " at step " + std::to_string(sim.currentStep()) + " of " +
                      std::to_string(steps) + "; checkpoint " + checkpoint);
    };
    const std::int64_t firstStep = sim.currentStep();
    while (sim.currentStep() < steps) {
      if (cancellationRequested()) cancelled("in the run phase");  // e.g. while the tracers were placed
      sim.step();
      const std::int64_t s = sim.currentStep();
      const bool stopForTest = options.stopAfterSteps >= 0 && s - firstStep >= options.stopAfterSteps;
      if (cancellationRequested() || stopForTest) cancelled("in the run phase");
      if (s % checkpointEvery == 0 && s < steps) save();
      progress.report(double(s) / double(steps), sim.time());
    }
    progress.setPhase("results");
    progress.report(1.0, sim.time(), true);
    // The run is complete: a checkpoint of its end leaves a resume only the results to write.
    auto pollInResults = [&] {
      if (cancellationRequested()) cancelled("while writing the results");
    };

    const double wall = priorWall + std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    nlohmann::json summary = {{"kind", job.kind},
                              {"status", "succeeded"},
                              {"seed", job.seed},
                              {"steps", steps},
                              {"sim_time_s", sim.time()},
                              {"dt", scene.rcfd.dt},
                              {"effects", sim.effectNames()}};
    pollInResults();
    {
      const std::string resultTmp = options.outDir + "/result.h5.tmp";
      h5::File out(resultTmp, h5::File::Mode::Create);
      out.writeString("/scene", scene.source_json);
      sim.writeResults(out, summary);
      out.write("/path/frames", std::vector<std::int64_t>(rec.path.frames.begin(), rec.path.frames.end()));
      out.flush();
    }
    std::filesystem::rename(options.outDir + "/result.h5.tmp", options.outDir + "/result.h5");
    pollInResults();
    summary["stay_comparison"] = stayComparison(job, scene, options.outDir + "/result.h5", steps);
    summary["coverage_comparison"] = coverageComparison(job, scene, options.outDir + "/result.h5",
                                                        sim.cloud().particlesPerTracer, sim.time());
    pollInResults();
    if (scene.outputs.svg) summary["figures"] = sim.writeFigures(options.outDir);
    summary["path"] = {{"jumps", rec.pathStats.jumps},
                       {"mean_jump_similarity", rec.pathStats.meanJumpSimilarity},
                       {"mean_sequence_frames", rec.pathStats.meanSequenceLength}};
    // Wall time and rates describe this machine, not the physics: the only keys allowed to differ
    // between otherwise bit-identical runs.
    summary["wall_time_s"] = wall;
    summary["tracer_steps_per_s"] = wall > 0.0 ? double(sim.cloud().size()) * double(steps) / wall : 0.0;
    std::filesystem::remove(checkpoint);
    return summary;
  }
};

const bool registered = JobRunnerRegistry::add("spray", "rCFD tracer run with the scene's effects",
                                               [] { return std::make_unique<TracerJob>(); });

}  // namespace
}  // namespace rcfd
