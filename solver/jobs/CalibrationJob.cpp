// The "calibration" job (the paper's section "Reproduction of bed distribution and dynamics in rCFD"):
// one tracer run per D0 value on one shared recurrence path, scored against the recurrence fields
// (probe penalty, time-averaged alpha_P) and, when the database carries them, the full simulation's
// spray-zone holdup and residence times; then the penalty minimum and the paper's choice of D0.
// Finished D0 runs live in DIR/runs/d0_<i>/ (result.h5, summary.json); a re-run skips them and resumes
// an interrupted one from its checkpoint. Aggregation: analysis/CalibrationReport.cpp.
//
// Cancellation (jobs/Cancellation.hpp) by phase, as the progress names them: "recurrence" (reading the
// database, its recurrence matrix, the path) polls between frames and tiles and keeps nothing; "runs"
// polls after every tracer step and checkpoints each unfinished run; "report" looks before it starts
// (it reads only the runs' small result files) and keeps the runs, so a resume writes the report again.
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <spdlog/spdlog.h>
#include <thread>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "analysis/CalibrationReport.hpp"
#include "analysis/CalibrationSelection.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "core/Errors.hpp"
#include "jobs/Cancellation.hpp"
#include "jobs/JobRunner.hpp"
#include "jobs/JobSupport.hpp"
#include "jobs/Progress.hpp"
#include "jobs/RecurrenceSetup.hpp"
#include "tracers/FluctuationModel.hpp"
#include "tracers/TracerSimulation.hpp"

namespace rcfd {
namespace {

namespace fs = std::filesystem;

/// The paper's range of D0 values [m2/s], used when the job gives none.
const std::vector<double> kDefaultD0 = {0.0, 1e-5, 1e-4, 5e-4, 1e-3, 1e-2};
/// Effects of every calibration run, whatever the scene lists...
const std::vector<std::string> kCalibrationEffects = {"transport", "free_flight", "walls", "tracer_volume_fraction",
                                                      "probes", "residence_time", "field_average"};
/// ...the relaxation models whose strength D0 is: those of the scene's list, Eq. (10)'s `fluctuation`
/// when it lists none...
const std::vector<std::string> kRelaxationModels = {"fluctuation", "directed_relaxation"};
/// ...and the motion models of the scene's list that change how tracers move (calibrated with them).
const std::vector<std::string> kCalibratedModels = {"velocity_streams", "langevin_velocity"};

std::vector<std::string> calibrationEffects(const Scene& scene) {
  std::vector<std::string> effects = {kCalibrationEffects.front()};
  for (const auto& m : kRelaxationModels) {
    if (scene.hasEffect(m)) effects.push_back(m);
  }
  if (effects.size() == 1) effects.push_back(kRelaxationModels.front());
  effects.insert(effects.end(), kCalibrationEffects.begin() + 1, kCalibrationEffects.end());
  for (const auto& m : kCalibratedModels) {
    if (scene.hasEffect(m)) effects.push_back(m);
  }
  return effects;
}

int threadBudget() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}


enum class RunOutcome { Finished, Stopped };

class CalibrationJob final : public JobRunner {
 public:
  nlohmann::json run(const JobSpec& job, const RunOptions& options) override {
    const auto wallStart = std::chrono::steady_clock::now();
    const Scene& scene = job.scene;
    if (job.database.empty()) throw InputError("job", "/database", "a calibration job needs a database");
    requireJobRules(job);
    const std::int64_t steps = std::llround(job.duration / scene.rcfd.dt);
    const std::int64_t discardSteps = std::llround(job.discard / scene.rcfd.dt);
    std::vector<double> d0 = job.d0_values.empty() ? kDefaultD0 : job.d0_values;
    const analysis::SelectionOptions selection = analysis::selectionOptionsFrom(job.source);
    const bool parallelOverD0 = parallelMode(job.source) == "d0_values";

    // Reference statistics first: the recurrence setup may rewrite the file (stored matrix).
    const analysis::ReferenceStatistics reference =
        analysis::readReferenceStatistics(job.database, &scene.spray.spray_zone);
    if (!reference.zoneMismatch.empty()) spdlog::warn("{}: {}", job.database, reference.zoneMismatch);
    for (const auto& m : reference.missing) {
      spdlog::warn("{}: no {} (reference statistics of the full simulation); scores that need it are not computed",
                   job.database, m);
    }
    const std::string runsDir = options.outDir + "/runs";
    double priorWall = 0.0;
    if (fs::exists(runsDir + "/prior_wall_time_s")) std::ifstream(runsDir + "/prior_wall_time_s") >> priorWall;
    // The settings a run of D0 value i is kept for (DIR/runs/d0_<i>/key.json).
    auto keyOf = [&](std::size_t i) -> nlohmann::json {
      return {{"d0", d0[i]},          {"seed", job.seed},       {"steps", steps},
              {"discard_steps", discardSteps}, {"tracers", scene.rcfd.tracers},
              {"dt", scene.rcfd.dt},  {"database", job.database},
              {"effects", calibrationEffects(scene)}};
    };
    // Steps done by earlier processes, counted before anything runs, so that this process's progress
    // and ETA start from them (a resumed run's steps are counted here, not when it is reached).
    std::vector<char> counted(d0.size(), 0);
    std::int64_t priorSteps = 0;
    for (std::size_t i = 0; i < d0.size(); ++i) {
      const std::string dir = runsDir + "/d0_" + std::to_string(i);
      if (!fs::exists(dir + "/key.json") || readJsonFile(dir + "/key.json") != keyOf(i)) continue;
      if (fs::exists(dir + "/summary.json")) {
        priorSteps += steps;
      } else if (fs::exists(dir + "/checkpoint.h5")) {
        h5::File f(dir + "/checkpoint.h5", h5::File::Mode::ReadOnly);
        if (!f.exists("/state/step")) continue;
        priorSteps += f.readInt64s("/state/step").at(0);
      }
      counted[i] = 1;
    }
    const double tracers = double(scene.rcfd.tracers);
    double totalSteps = double(steps) * double(d0.size());
    // The recurrence set-up and the runs' tracer steps weighted by their expected cost.
    TracerJobWork work(recurrenceWork(scene, job.database), totalSteps * tracers);
    std::atomic<std::int64_t> stepsThisProcess{0}, stepsDone{priorSteps};
    auto fraction = [&](double recurrenceDone) { return work.fraction(recurrenceDone, double(stepsDone) * tracers); };

    ProgressReporter progress(options.progressJson, options.progressInterval, "calibration ");
    progress.setPriorWallTime(priorWall);
    progress.setStartFraction(fraction(0.0));
    progress.setPhase("recurrence");
    progress.setPhaseFraction(0.0);
    progress.report(fraction(0.0), 0.0, true);

    // One path for every D0 (the paper used a precomputed path to remove path randomness).
    const RecurrenceSetup rec = prepareRecurrence(scene, job.database, steps + 2, job.seed,
                                                  [] { return cancellationRequested(); },
                                                  [&](double f) {
                                                    progress.setPhaseFraction(f);
                                                    progress.report(fraction(f), 0.0);
                                                  });
    fs::create_directories(runsDir);

    // --- the D0 runs ---
    std::atomic<bool> stop{false};
    std::mutex mutex;  // progress reporter and the first error
    std::exception_ptr error;

    auto runOne = [&](std::size_t i) -> RunOutcome {
      const std::string dir = runsDir + "/d0_" + std::to_string(i);
      const nlohmann::json key = keyOf(i);
      const bool alreadyCounted = i < counted.size() && counted[i];
      if (fs::exists(dir + "/key.json") && readJsonFile(dir + "/key.json") != key) {
        spdlog::warn("{} holds a run of other settings; starting D0 = {} afresh", dir, d0[i]);
        fs::remove_all(dir);
      }
      if (fs::exists(dir + "/summary.json")) {
        if (!alreadyCounted) stepsDone += steps;
        return RunOutcome::Finished;  // finished by an earlier process
      }
      if (cancellationRequested()) {  // not worth setting up a run only to checkpoint its first step
        stop = true;
        return RunOutcome::Stopped;
      }
      fs::create_directories(dir);
      writeFileAtomically(dir + "/key.json", key.dump() + "\n");

      Scene s = scene;
      s.rcfd.d0 = d0[i];
      s.effects = calibrationEffects(scene);
      TracerSimulation sim(s, rec.database, rec.path, TracerRunSettings{job.seed, steps, discardSteps});
      const std::string checkpoint = dir + "/checkpoint.h5";
      if (fs::exists(checkpoint)) {
        sim.loadCheckpoint(checkpoint);
        spdlog::info("D0 = {}: resumed at step {} of {}", d0[i], sim.currentStep(), steps);
      }
      if (!alreadyCounted) stepsDone += sim.currentStep();
      const std::int64_t checkpointEvery =
          std::max<std::int64_t>(1, std::llround(job.checkpoint_interval / scene.rcfd.dt));
      while (sim.currentStep() < steps) {
        sim.step();
        ++stepsDone;
        const std::int64_t done = ++stepsThisProcess;
        if (options.stopAfterSteps >= 0 && done >= options.stopAfterSteps) stop = true;
        if (stop || cancellationRequested()) {
          stop = true;
          const ForcedExitDeferral keepTheCheckpoint;
          sim.saveCheckpoint(checkpoint);
          return RunOutcome::Stopped;
        }
        if (sim.currentStep() % checkpointEvery == 0 && sim.currentStep() < steps) {
          const ForcedExitDeferral keepTheCheckpoint;
          sim.saveCheckpoint(checkpoint);
        }
        if (mutex.try_lock()) {
          progress.setPhaseFraction(double(stepsDone) / totalSteps);
          progress.report(fraction(1.0), double(stepsDone) * scene.rcfd.dt);  // summed over D0
          mutex.unlock();
        }
      }
      nlohmann::json summary = {{"d0", d0[i]}, {"key", key}};
      {
        h5::File out(dir + "/result.h5.tmp", h5::File::Mode::Create);
        sim.writeResults(out, summary);
        out.flush();
      }
      fs::rename(dir + "/result.h5.tmp", dir + "/result.h5");
      xdmf::writeSidecar(dir + "/result.h5", xdmfGrid(rec.database->grid()));
      writeFileAtomically(dir + "/summary.json", summary.dump(2) + "\n");
      fs::remove(checkpoint);
      spdlog::info("D0 = {} m2/s: penalty {:.4g}", d0[i], summary["probes"]["penalty_mean"].get<double>());
      return RunOutcome::Finished;
    };
    auto guarded = [&](std::size_t i) {
      try {
        runOne(i);
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!error) error = std::current_exception();
        stop = true;
      }
    };

    // Runs [first, last) of the list, in parallel over the thread budget.
    auto runRange = [&](std::size_t first, std::size_t last) {
      const std::size_t count = last - first;
      const int budget = std::max(1, threadBudget());
      const int workers = parallelOverD0 ? int(std::min<std::size_t>(std::size_t(budget), count)) : 1;
      const int threadsPerRun = std::max(1, budget / workers);
      spdlog::info("calibration: {} D0 values x {} steps; {} run(s) at a time with {} thread(s) each", count, steps,
                   workers, threadsPerRun);
      if (workers <= 1) {
        for (std::size_t i = first; i < last && !stop; ++i) guarded(i);
      } else {
        std::atomic<std::size_t> next{first};
        std::vector<std::thread> pool;
        for (int w = 0; w < workers; ++w) {
          pool.emplace_back([&] {
            setRunThreads(threadsPerRun);
            for (std::size_t i = next++; i < last && !stop; i = next++) guarded(i);
          });
        }
        for (auto& t : pool) t.join();
      }
      const double wall = priorWall + progress.wallTime();
      if (error) std::rethrow_exception(error);
      if (stop || cancellationRequested()) {
        writeFileAtomically(runsDir + "/prior_wall_time_s", std::to_string(wall) + "\n");
        throw Cancelled("calibration stopped in the " + progress.phase() +
                        " phase; finished D0 runs and checkpoints are kept in " + runsDir);
      }
    };

    // --- runs, scores and selection; the sweep grows while its optimum lies at its upper end ---
    // Beyond the D0 at which Eq. (10)'s largest speed reaches u_fluc_max the cap decides, not D0.
    const double bindingD0 = [&] {
      const auto model = FluctuationModelRegistry::create(scene.rcfd.fluctuation_model);
      const double unit = model->speed(1.0, 0.0, 1.0, scene.rcfd.dt);  // the largest speed at D0 = 1
      return unit > 0.0 ? std::pow(scene.rcfd.u_fluc_max / unit, 2) : 0.0;
    }();
    nlohmann::json summary;
    nlohmann::json extension = {{"added", nlohmann::json::array()}, {"binding_d0", bindingD0}};
    for (std::size_t first = 0;;) {
      progress.setPhase("runs");
      progress.setPhaseFraction(double(stepsDone) / totalSteps);
      progress.report(fraction(1.0), double(stepsDone) * scene.rcfd.dt, true);
      runRange(first, d0.size());
      first = d0.size();
      progress.setPhase("report");
      progress.report(fraction(1.0), double(stepsDone) * scene.rcfd.dt, true);
      analysis::CalibrationInputs inputs{scene, *rec.database, d0, runsDir, reference, selection, steps, discardSteps};
      summary = analysis::writeCalibrationReport(inputs, options.outDir + "/result.h5",
                                                 scene.outputs.svg ? options.outDir : std::string());
      if (!summary["selection"]["at_upper_end"].get<bool>()) break;
      const double top = *std::max_element(d0.begin(), d0.end());
      if (!selection.extendSweep) {
        extension["stopped"] = "the optimum is at the largest D0 of the sweep; extend_sweep is off";
        break;
      }
      if (!(top < bindingD0 * (1.0 - 1e-9))) {
        extension["stopped"] = "the optimum is at the largest D0 of the sweep, where u_fluc_max already binds: "
                               "a larger D0 changes nothing";
        break;
      }
      const double next = std::min(bindingD0, top > 0.0 ? top * selection.sweepFactor : 1e-5);
      spdlog::info("calibration: the optimum is at the upper end of the sweep (D0 = {} m2/s); adding D0 = {} m2/s",
                   top, next);
      d0.push_back(next);
      extension["added"].push_back(next);
      totalSteps = double(steps) * double(d0.size());
      work.setTracerSteps(totalSteps * tracers);
    }
    summary["sweep_extension"] = extension;
    progress.report(1.0, totalSteps * scene.rcfd.dt, true);
    {
      h5::File out(options.outDir + "/result.h5", h5::File::Mode::ReadWrite);
      out.write("/path/frames", std::vector<std::int64_t>(rec.path.frames.begin(), rec.path.frames.end()));
    }
    {
      // The report's fields are mid-plane maps of one cell layer: the recurrence average and each run's.
      const CartesianGrid& grid = rec.database->grid();
      const std::int64_t layer = analysis::midplaneLayer(scene, grid);
      std::vector<xdmf::LayerMap> maps{{"/calibration/recurrence/alpha_p_midplane", layer}};
      for (std::size_t i = 0; i < d0.size(); ++i)
        maps.push_back({"/calibration/runs/d0_" + std::to_string(i) + "/field_average/alpha_p_midplane", layer});
      xdmf::writeSidecar(options.outDir + "/result.h5", xdmfGrid(grid), maps);
    }
    summary["kind"] = job.kind;
    summary["status"] = "succeeded";
    summary["seed"] = job.seed;
    summary["steps"] = steps;  // per D0
    summary["sim_time_s"] = double(steps) * scene.rcfd.dt;
    summary["discard_s"] = double(discardSteps) * scene.rcfd.dt;
    summary["dt"] = scene.rcfd.dt;
    summary["tracers"] = scene.rcfd.tracers;
    summary["effects"] = calibrationEffects(scene);
    summary["frame_spacing"] = toJson(rec.frameSpacing);
    summary["path"] = {{"jumps", rec.pathStats.jumps},
                       {"mean_jump_similarity", rec.pathStats.meanJumpSimilarity},
                       {"mean_sequence_frames", rec.pathStats.meanSequenceLength}};
    // Wall time describes this machine, not the physics: the only key allowed to differ between
    // otherwise bit-identical runs.
    summary["wall_time_s"] = priorWall + std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    fs::remove(runsDir + "/prior_wall_time_s");
    return summary;
  }

 private:
  static std::string parallelMode(const nlohmann::json& document) {
    const std::string fallback = "d0_values";
    if (!document.is_object() || !document.contains("calibration")) return fallback;
    const auto& c = document["calibration"];
    if (!c.is_object() || !c.contains("parallel")) return fallback;
    const auto& v = c["parallel"];
    if (!v.is_string() || (v != "d0_values" && v != "tracers")) {
      throw InputError("job", "/calibration/parallel", "must be \"d0_values\" or \"tracers\"");
    }
    return v.get<std::string>();
  }
};

const bool registered = JobRunnerRegistry::add(
    "calibration", "rCFD tracer runs for each D0 scored against the recurrence fields and the full simulation",
    [] { return std::make_unique<CalibrationJob>(); });

}  // namespace
}  // namespace rcfd
