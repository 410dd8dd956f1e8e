// The "spray" job: a tracer simulation with the scene's effects on an existing database, for
// `duration` simulated seconds, with checkpoints, resume and progress. (Spray deposition itself plugs in
// as further effects.) With `"ensemble": K` (K > 1) it runs K members, each the job of its own seed,
// side by side on the one database (runEnsemble below, jobs/Ensemble.hpp).
//
// Cancellation (jobs/Cancellation.hpp) by phase, as the progress names them: "recurrence" (reading the
// database, its recurrence matrix, the path) polls between frames and tiles and keeps nothing; "run"
// polls after every tracer step and checkpoints; "results" looks between its parts and checkpoints the
// finished run, so a resume only writes the results again. An ensemble checkpoints each unfinished
// member in "run" and keeps the finished ones (DIR/members/NN/), from which "results" is written again.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <spdlog/spdlog.h>
#include <thread>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "analysis/CoverageComparison.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "analysis/StayComparison.hpp"
#include "core/Errors.hpp"
#include "jobs/Cancellation.hpp"
#include "jobs/Ensemble.hpp"
#include "jobs/JobRunner.hpp"
#include "jobs/JobSupport.hpp"
#include "jobs/Progress.hpp"
#include "jobs/RecurrenceSetup.hpp"
#include "spray/Coverage.hpp"
#include "tracers/TracerSimulation.hpp"

namespace rcfd {
namespace {

/// The run's spray-zone stays against the full simulation's reference in the database, on the tracers'
/// step lattice (analysis/StayComparison.hpp); null without residence_time or without a reference.
nlohmann::json stayComparison(const JobSpec& job, const Scene& scene, const std::string& resultPath,
                              std::int64_t steps, double holdupMean) {
  analysis::ReferenceStatistics reference;
  try {
    reference = analysis::readReferenceStatistics(job.database, &scene.spray.spray_zone);
  } catch (const InputError& e) {  // a damaged reference must not cost the finished run its summary
    spdlog::warn("no stay comparison: {}", e.what());
    return {{"error", e.what()}};
  }
  if (!reference.zoneMismatch.empty()) {
    spdlog::warn("no stay comparison: {}", reference.zoneMismatch);
    return {{"error", reference.zoneMismatch}};
  }
  h5::File result(resultPath, h5::File::Mode::ReadOnly);
  const char* counts = "/residence_time/duration_steps_counts";
  if (!reference.hasDurations() || !result.exists(counts)) return nullptr;
  const double members = analysis::referenceMembers(reference, scene.process.bed_mass, scene.particles.density,
                                                    scene.particles.diameter);
  const std::vector<std::int64_t> stepCounts = result.readInt64s(counts);
  nlohmann::json out = analysis::compareStays(stepCounts, scene.rcfd.dt, double(scene.rcfd.tracers),
                                              double(steps) * scene.rcfd.dt, reference.durations, members,
                                              reference.recordedPeriod())
                           .toJson();
  if (reference.sampledPeriod) {
    out["against_sampled_period"] =
        analysis::compareWithPeriod(*reference.sampledPeriod, stepCounts, scene.rcfd.dt, double(scene.rcfd.tracers),
                                    double(steps) * scene.rcfd.dt, holdupMean, members);
  }
  return out;
}

/// Opens the recurrence set-up's phase of a run that has `priorWall` seconds and `startFraction` of its
/// work behind it (a resumed job): its first line, at once, and the ETA counted from this process on.
void beginRecurrencePhase(ProgressReporter& progress, double priorWall, double startFraction) {
  progress.setPriorWallTime(priorWall);
  progress.setStartFraction(startFraction);
  progress.setPhase("recurrence");
  progress.setPhaseFraction(0.0);
  progress.report(startFraction, 0.0, true);
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

/// What a finished run writes, alike for a spray job and each member of an ensemble: `dir`/result.h5
/// (through a temporary and a rename) and the summary without the machine's figures (wall time,
/// rates); figures into `figureDir` (none when empty). `poll` is called between the parts.
nlohmann::json writeRunResults(const JobSpec& job, const TracerSimulation& sim, std::uint64_t seed,
                               std::int64_t steps, const RecurrencePath& path, const PathStatistics& pathStats,
                               const FrameSpacing& spacing, const std::string& dir, const std::string& figureDir,
                               const std::function<void()>& poll) {
  const Scene& scene = job.scene;
  nlohmann::json summary = {{"kind", job.kind},
                            {"status", "succeeded"},
                            {"seed", seed},
                            {"steps", steps},
                            {"sim_time_s", sim.time()},
                            {"dt", scene.rcfd.dt},
                            {"effects", sim.effectNames()}};
  poll();
  {
    const std::string resultTmp = dir + "/result.h5.tmp";
    h5::File out(resultTmp, h5::File::Mode::Create);
    out.writeString("/scene", scene.source_json);
    sim.writeResults(out, summary);
    out.write("/path/frames", std::vector<std::int64_t>(path.frames.begin(), path.frames.end()));
    out.flush();
  }
  std::filesystem::rename(dir + "/result.h5.tmp", dir + "/result.h5");
  xdmf::writeSidecar(dir + "/result.h5", xdmfGrid(sim.context().grid));
  poll();
  summary["stay_comparison"] =
      stayComparison(job, scene, dir + "/result.h5", steps, summary.value(nlohmann::json::json_pointer("/holdup/mean"), 0.0));
  summary["coverage_comparison"] =
      coverageComparison(job, scene, dir + "/result.h5", sim.cloud().particlesPerTracer, sim.time());
  poll();
  if (scene.outputs.svg && !figureDir.empty()) summary["figures"] = sim.writeFigures(figureDir);
  summary["frame_spacing"] = toJson(spacing);
  summary["path"] = {{"jumps", pathStats.jumps},
                     {"mean_jump_similarity", pathStats.meanJumpSimilarity},
                     {"mean_sequence_frames", pathStats.meanSequenceLength}};
  return summary;
}

int threadBudget() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}


class TracerJob final : public JobRunner {
 public:
  nlohmann::json run(const JobSpec& job, const RunOptions& options) override {
    if (job.database.empty()) throw InputError("job", "/database", "a spray job needs a database");
    if (job.ensemble_members < 1 || job.ensemble_members > kMaxEnsembleMembers) {
      throw InputError("job", "/ensemble", std::to_string(job.ensemble_members) + " members; allowed: [1, " +
                                               std::to_string(kMaxEnsembleMembers) + "]");
    }
    requireJobRules(job);
    return job.ensemble_members == 1 ? runSingle(job, options) : runEnsemble(job, options);
  }

 private:
  /// One run of the job's seed: checkpoint.h5, result.h5 and the figures in the output directory.
  nlohmann::json runSingle(const JobSpec& job, const RunOptions& options) {
    const Scene& scene = job.scene;
    const auto wallStart = std::chrono::steady_clock::now();
    const std::int64_t steps = std::llround(job.duration / scene.rcfd.dt);

    const std::string checkpoint = options.outDir + "/checkpoint.h5";
    double priorWall = 0.0;
    std::int64_t resumedStep = 0;
    if (std::filesystem::exists(checkpoint)) {
      h5::File f(checkpoint, h5::File::Mode::ReadOnly);
      if (f.exists("/state/wall_time")) priorWall = f.readDoubles("/state/wall_time").at(0);
      if (f.exists("/state/step")) resumedStep = f.readInt64s("/state/step").at(0);
    }
    // The recurrence set-up and the tracer steps weighted by their expected cost (RecurrenceWork).
    const TracerJobWork work(recurrenceWork(scene, job.database), double(steps) * double(scene.rcfd.tracers));
    const double tracers = double(scene.rcfd.tracers);
    ProgressReporter progress(options.progressJson, options.progressInterval);
    beginRecurrencePhase(progress, priorWall, work.fraction(0.0, double(resumedStep) * tracers));

    // The path is indexed per frame; dt may divide dt_rec, so size it for the number of frames used.
    RecurrenceSetup rec = prepareRecurrence(scene, job.database, steps + 2, job.seed,
                                            [] { return cancellationRequested(); },
                                            [&](double f) {
                                              progress.setPhaseFraction(f);
                                              progress.report(work.fraction(f, double(resumedStep) * tracers), 0.0);
                                            });
    TracerRunSettings settings{job.seed, steps, 0};
    TracerSimulation sim(scene, rec.database, rec.path, settings);
    if (std::filesystem::exists(checkpoint)) {
      sim.loadCheckpoint(checkpoint);
      spdlog::info("resumed from {} at step {} of {}", checkpoint, sim.currentStep(), steps);
    }
    const std::int64_t checkpointEvery =
        std::max<std::int64_t>(1, std::llround(job.checkpoint_interval / scene.rcfd.dt));

    auto fraction = [&] { return work.fraction(1.0, double(sim.currentStep()) * tracers); };
    progress.setPhase("run");
    progress.setPhaseFraction(double(sim.currentStep()) / double(steps));
    progress.report(fraction(), sim.time(), true);
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
      progress.setPhaseFraction(double(s) / double(steps));
      progress.report(fraction(), sim.time());
    }
    progress.setPhase("results");
    progress.report(1.0, sim.time(), true);
    // The run is complete: a checkpoint of its end leaves a resume only the results to write.
    auto pollInResults = [&] {
      if (cancellationRequested()) cancelled("while writing the results");
    };

    const double wall = priorWall + std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    nlohmann::json summary = writeRunResults(job, sim, job.seed, steps, rec.path, rec.pathStats, rec.frameSpacing,
                                             options.outDir, options.outDir, pollInResults);
    // Wall time and rates describe this machine, not the physics: the only keys allowed to differ
    // between otherwise bit-identical runs.
    summary["wall_time_s"] = wall;
    summary["tracer_steps_per_s"] = wall > 0.0 ? double(sim.cloud().size()) * double(steps) / wall : 0.0;
    std::filesystem::remove(checkpoint);
    return summary;
  }

  /// K members, each the run of its seed in DIR/members/NN/ (checkpoint.h5 while it runs; result.h5
  /// and summary.json once finished, which a resume keeps), run side by side over the job's threads;
  /// then the job's result.h5, summary and figures from them (Ensemble.hpp).
  ///
  /// The threads: min(threads, K) workers take the members in order, each member's steps on
  /// threads / (workers still running) OpenMP threads (on 2 cores: two members at a time on one thread
  /// each, the last one on both). Members share nothing but the database and the recurrence matrix, so
  /// side by side they scale with the cores without a barrier per step (a member's step on 2 threads
  /// gains less: its spray, frame loading and sorting do not split); a member's results do not depend
  /// on its thread count, so neither do the job's.
  nlohmann::json runEnsemble(const JobSpec& job, const RunOptions& options) {
    namespace fs = std::filesystem;
    const Scene& scene = job.scene;
    const auto wallStart = std::chrono::steady_clock::now();
    const std::int64_t steps = std::llround(job.duration / scene.rcfd.dt);
    const int members = job.ensemble_members;
    const std::vector<std::uint64_t> seeds = ensembleSeeds(job.seed, members);
    const std::string membersDir = options.outDir + "/members";
    auto memberDir = [&](int k) { return membersDir + "/" + ensembleMemberName(std::size_t(k)); };
    // A member is finished when its summary (of its seed) and result are there.
    auto finished = [&](int k) {
      const std::string dir = memberDir(k);
      if (!fs::exists(dir + "/summary.json") || !fs::exists(dir + "/result.h5")) return false;
      const auto s = readJsonFile(dir + "/summary.json");
      return s.contains("seed") && s["seed"].get<std::uint64_t>() == seeds[std::size_t(k)];
    };

    double priorWall = 0.0;
    if (fs::exists(membersDir + "/prior_wall_time_s")) std::ifstream(membersDir + "/prior_wall_time_s") >> priorWall;
    // Steps already done: finished members and checkpoints of a resumed job.
    const double totalSteps = double(steps) * double(members);
    std::atomic<std::int64_t> stepsDone{0}, stepsThisProcess{0};
    for (int k = 0; k < members; ++k) {
      const std::string checkpoint = memberDir(k) + "/checkpoint.h5";
      if (finished(k)) {
        stepsDone += steps;
      } else if (fs::exists(checkpoint)) {
        h5::File f(checkpoint, h5::File::Mode::ReadOnly);
        stepsDone += f.readInt64s("/state/step").at(0);
      }
    }
    // The recurrence set-up and the members' tracer steps weighted by their expected cost.
    const double tracers = double(scene.rcfd.tracers);
    const TracerJobWork work(recurrenceWork(scene, job.database), totalSteps * tracers);
    ProgressReporter progress(options.progressJson, options.progressInterval);
    beginRecurrencePhase(progress, priorWall, work.fraction(0.0, double(stepsDone) * tracers));
    // One matrix and database for all; member 0's path is the job seed's, the others draw their own.
    RecurrenceSetup rec = prepareRecurrence(scene, job.database, steps + 2, job.seed,
                                            [] { return cancellationRequested(); },
                                            [&](double f) {
                                              progress.setPhaseFraction(f);
                                              progress.report(work.fraction(f, double(stepsDone) * tracers), 0.0);
                                            });
    fs::create_directories(membersDir);
    const std::int64_t checkpointEvery =
        std::max<std::int64_t>(1, std::llround(job.checkpoint_interval / scene.rcfd.dt));
    const int budget = std::max(1, threadBudget());
    const int workers = std::min(budget, members);
    std::atomic<int> running{workers};
    std::atomic<bool> stop{false};
    std::mutex mutex;  // the progress reporter and the first error
    std::exception_ptr error;
    spdlog::info("ensemble: {} members x {} steps; {} at a time on {} thread(s)", members, steps, workers, budget);
    progress.setPhase("run");
    progress.setPhaseFraction(double(stepsDone) / totalSteps);
    progress.report(work.fraction(1.0, double(stepsDone) * tracers), double(stepsDone) * scene.rcfd.dt, true);

    auto runMember = [&](int k) {
      if (finished(k)) return;
      const std::string dir = memberDir(k);
      fs::create_directories(dir);
      const std::uint64_t seed = seeds[std::size_t(k)];
      setRunThreads(std::max(1, budget / running));
      PathStatistics pathStats = rec.pathStats;
      const RecurrencePath path =
          k == 0 ? rec.path : generateRecurrencePath(scene, rec.matrix, steps + 2, seed, &pathStats);
      TracerSimulation sim(scene, rec.database, path, TracerRunSettings{seed, steps, 0});
      const std::string checkpoint = dir + "/checkpoint.h5";
      if (fs::exists(checkpoint)) {
        sim.loadCheckpoint(checkpoint);
        spdlog::info("member {}: resumed at step {} of {}", k, sim.currentStep(), steps);
      }
      auto save = [&] {
        const ForcedExitDeferral keepTheCheckpoint;
        sim.saveCheckpoint(checkpoint);
      };
      while (sim.currentStep() < steps) {
        if (stop || cancellationRequested()) {
          stop = true;
          save();
          return;
        }
        setRunThreads(std::max(1, budget / running));
        sim.step();
        ++stepsDone;
        const std::int64_t done = ++stepsThisProcess;
        if (options.stopAfterSteps >= 0 && done >= options.stopAfterSteps) stop = true;
        if (sim.currentStep() % checkpointEvery == 0 && sim.currentStep() < steps) save();
        if (mutex.try_lock()) {
          progress.setPhaseFraction(double(stepsDone) / totalSteps);
          progress.report(work.fraction(1.0, double(stepsDone) * tracers), double(stepsDone) * scene.rcfd.dt);
          mutex.unlock();
        }
      }
      // Finished: a stop while the results are written keeps the end as the checkpoint.
      auto poll = [&] {
        if (cancellationRequested()) {
          stop = true;
          save();
          throw Cancelled("member " + std::to_string(k) + " stopped while writing its results");
        }
      };
      nlohmann::json summary =
          writeRunResults(job, sim, seed, steps, path, pathStats, rec.frameSpacing, dir, k == 0 ? options.outDir : std::string(), poll);
      writeFileAtomically(dir + "/summary.json", summary.dump(2) + "\n");
      fs::remove(checkpoint);
    };
    std::atomic<int> next{0};
    auto worker = [&] {
      try {
        for (int k = next++; k < members && !stop; k = next++) runMember(k);
      } catch (const Cancelled&) {
        stop = true;
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!error) error = std::current_exception();
        stop = true;
      }
      --running;
    };
    if (workers == 1) {
      worker();
    } else {
      std::vector<std::thread> pool;
      for (int w = 0; w < workers; ++w) pool.emplace_back(worker);
      for (auto& t : pool) t.join();
    }
    setRunThreads(budget);
    if (error) std::rethrow_exception(error);
    bool allFinished = true;
    for (int k = 0; k < members && allFinished; ++k) allFinished = finished(k);
    if (!allFinished) {
      writeFileAtomically(membersDir + "/prior_wall_time_s", std::to_string(priorWall + progress.wallTime()) + "\n");
      throw Cancelled("ensemble stopped in the run phase after " + std::to_string(stepsDone.load()) + " of " +
                      std::to_string(std::int64_t(totalSteps)) + " member steps; checkpoints in " + membersDir);
    }

    // --- the job's results from the members' (a stop here keeps them: a resume writes these again) ---
    progress.setPhase("results");
    progress.report(1.0, totalSteps * scene.rcfd.dt, true);
    auto pollInResults = [&] {
      if (cancellationRequested()) {
        writeFileAtomically(membersDir + "/prior_wall_time_s", std::to_string(priorWall + progress.wallTime()) + "\n");
        throw Cancelled("ensemble stopped while writing the results; the finished members are kept in " + membersDir);
      }
    };
    std::vector<nlohmann::json> memberSummaries;
    std::vector<std::string> memberFiles;
    for (int k = 0; k < members; ++k) {
      memberSummaries.push_back(readJsonFile(memberDir(k) + "/summary.json"));
      memberFiles.push_back(memberDir(k) + "/result.h5");
    }
    nlohmann::json summary = memberSummaries.front();
    summary["ensemble"] = ensembleSummary(memberSummaries, seeds);
    pollInResults();
    {
      const std::string resultTmp = options.outDir + "/result.h5.tmp";
      fs::copy_file(memberFiles.front(), resultTmp, fs::copy_options::overwrite_existing);
      h5::File out(resultTmp, h5::File::Mode::ReadWrite);
      writeEnsembleResults(out, summary["ensemble"], memberFiles, memberSummaries);
      out.flush();
    }
    fs::rename(options.outDir + "/result.h5.tmp", options.outDir + "/result.h5");
    xdmf::writeSidecar(options.outDir + "/result.h5", xdmfGrid(rec.database->grid()));
    pollInResults();
    if (scene.outputs.svg && summary["ensemble"].contains(nlohmann::json::json_pointer("/coverage/histogram"))) {
      writeEnsembleCoverageFigure(summary["ensemble"], double(steps) * scene.rcfd.dt, options.outDir);
    }
    const double wall = priorWall + std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    summary["wall_time_s"] = wall;
    summary["tracer_steps_per_s"] =
        wall > 0.0 ? double(summary["tracers"].get<double>()) * totalSteps / wall : 0.0;
    // The summary first, then the members' files (their content is in result.h5): a stop between the
    // two leaves a finished job, never one without its members.
    writeFileAtomically(options.outDir + "/summary.json", summary.dump(2) + "\n");
    fs::remove_all(membersDir);
    return summary;
  }
};

const bool registered = JobRunnerRegistry::add("spray", "rCFD tracer run with the scene's effects",
                                               [] { return std::make_unique<TracerJob>(); });

}  // namespace
}  // namespace rcfd
