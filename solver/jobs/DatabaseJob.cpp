// The "database" job (issue 7): the built-in CFD-DEM of the scene sampled into a recurrence field
// database. Phases, in whole DEM steps (scene/DatabaseSchedule.hpp): fill and settle (DEM only), a
// linear ramp of the gas flows, a warm-up at full flow, frames of alpha_P, u_P and u_G (and the velocity
// spread when a tracer effect of the scene reads it) every dt_rec for
// sample_duration (appended to DIR/database.h5 as they come), then the reference period. Throughout
// the sampled and reference periods the reference series (probe u_P,y, pressure drop; spray-zone holdup
// and stays in the reference period) are recorded every 1/probe_rate (cfddem/ReferenceRecorder.hpp)
// and written under /reference/ at the end; a scene that asks for the coverage also gets the coverage
// its spray model gives on the parcels themselves over the reference period
// (spray/ReferenceCoverage.hpp). A scene without the effect `gas` runs the DEM only.
//
// Checkpoints (DIR/checkpoint.h5, every checkpoint_interval and on cancellation) hold the simulation
// state and the job's counters; a resumed job cuts database.h5 back to the frames sampled before the
// checkpoint and goes on from there, so it writes what an uninterrupted job writes.
//
// Cancellation (jobs/Cancellation.hpp) by phase, as the progress names them: "fill" and "settle" poll
// before every DEM step and stop without a checkpoint (a half-filled bed is no state to resume from);
// "ramp", "warmup", "sample" and "reference" poll after every coupling step and checkpoint; "results"
// (reference series, result.h5, figures) polls between frames it reads and checkpoints the finished
// run, so a resume only writes the results again.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <spdlog/spdlog.h>

#include "analysis/DatabaseFigures.hpp"
#include "cfddem/CfdDemSimulation.hpp"
#include "cfddem/gas/GasSolver.hpp"
#include "scene/DatabaseSchedule.hpp"
#include "cfddem/ReferenceRecorder.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/FieldDatabase.hpp"
#include "fields/VelocityCompletion.hpp"
#include "jobs/Cancellation.hpp"
#include "jobs/DatabaseProgress.hpp"
#include "jobs/JobRunner.hpp"
#include "jobs/JobSupport.hpp"
#include "jobs/Progress.hpp"
#include "spray/ReferenceCoverage.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

namespace fs = std::filesystem;

/// Checkpoint group of the reference coverage's state.
constexpr const char* kCoverageGroup = "/reference_coverage";

/// The scene's effects that belong to the CFD-DEM stage (x-stage "cfd_dem" in the schema).
std::vector<std::string> cfdDemEffects(const Scene& scene) {
  const auto schema = nlohmann::json::parse(schemaText("scene"));
  std::vector<std::string> out;
  for (const auto& o : schema.at("properties").at("effects").at("items").at("oneOf")) {
    const std::string name = o.at("const");
    if (o.value("x-stage", "") == "cfd_dem" && scene.hasEffect(name)) out.push_back(name);
  }
  return out;
}

std::vector<float> interleaved(const std::vector<Eigen::Vector3d>& values) {
  std::vector<float> out(3 * values.size());
  for (std::size_t c = 0; c < values.size(); ++c)
    for (int d = 0; d < 3; ++d) out[3 * c + std::size_t(d)] = float(values[c][d]);
  return out;
}

/// Layers of cells around the parcels that the smoothing of Eq. (3) gives particle volume and the
/// frame its velocity (VelocityCompletion.hpp): the smoothing length is below a cell, so three layers
/// reach all but a negligible share of the smoothed volume.
constexpr int kSmoothedLayers = 3;

/// A frame of the current instant; with the velocity spread when `withSpread` (a scene whose tracer
/// effects read it: 17 floats per cell instead of 7, on disk and in every reader's memory). Cells that
/// only the smoothing gave particle volume get the velocity of the volume next to them.
FieldFrame sampleFrame(const CfdDemSimulation& sim, const std::vector<float>& openFraction, bool withSpread) {
  FieldFrame f;
  const auto alpha = sim.scene().dem.frame_alpha_p == "parcels" ? sim.parcelFraction() : sim.particleFraction();
  f.alpha_p.assign(alpha.begin(), alpha.end());
  f.u_g = interleaved(sim.gasVelocity());
  if (!withSpread) {
    f.u_p = interleaved(sim.particleVelocity());
  } else {
    const auto spread = sim.particleVelocitySpread();
    f.u_p = interleaved(spread.mean);
    f.up_fraction.assign(spread.upFraction.begin(), spread.upFraction.end());
    f.u_p_up = interleaved(spread.up);
    f.u_p_down = interleaved(spread.down);
    f.u_p_variance = interleaved(spread.variance);
  }
  completeParticleVelocity(sim.grid(), openFraction, sim.cellsHoldingParcels(), f, kSmoothedLayers);
  return f;
}

/// The job's own counters, saved beside the simulation state.
struct JobState {
  bool settled = false;
  std::int64_t settledStep = 0;   ///< DEM clock when settling ended (offset 0 of the schedule)
  std::int64_t framesWritten = 0;
  std::int64_t couplingSteps = 0;
  double wallTime = 0.0;          ///< wall seconds of earlier processes
  /// Highest parcel top (y + r) seen at the reference samples [m]; the DEM's outlet is a wall, so
  /// this is how the job tells that no parcel came near blowing out.
  double highestParcelTop = -std::numeric_limits<double>::infinity();
  double highestParcelTime = 0.0;  ///< when it was seen [s]
  /// Per parcel, 1 once its top came within one parcel diameter of the chamber top at a sample: the
  /// parcels an open outlet could have lost.
  std::vector<std::int64_t> reachedTop;
  FillResult fill;
};

class DatabaseJob final : public JobRunner {
 public:
  nlohmann::json run(const JobSpec& job, const RunOptions& options) override {
    const Scene& scene = job.scene;
    const DatabaseSchedule plan = DatabaseSchedule::fromScene(scene);
    const auto wallStart = std::chrono::steady_clock::now();
    const std::string checkpoint = options.outDir + "/checkpoint.h5";
    const std::string databasePath = options.outDir + "/database.h5";

    gas::GasOptions gasOptions;
    if (options.maxPressureIterations > 0) gasOptions.maxPressureIterations = options.maxPressureIterations;
    CfdDemSimulation sim(scene, job.seed, gasOptions);
    const std::vector<double> open = openFractions(sim.apparatus(), sim.grid());
    const std::vector<float> fluid(open.begin(), open.end());
    if (cancellationRequested()) throw Cancelled("stopped while setting up the simulation; nothing was written");

    JobState st;
    std::unique_ptr<ReferenceRecorder> rec;
    std::unique_ptr<ReferenceCoverage> coverage;
    std::unique_ptr<FieldDatabaseWriter> writer;
    auto makeRecorder = [&] {
      rec = std::make_unique<ReferenceRecorder>(scene, sim.grid(), sim.dem().particles().size(), plan.sampleDt(),
                                                plan.sampledSamples());
      if (ReferenceCoverage::wanted(scene) && sim.hasGas() && plan.referenceSamples > 0) {
        coverage = std::make_unique<ReferenceCoverage>(scene, sim.apparatus(), sim.grid(), open,
                                                       sim.dem().particles().size(), plan.sampleDt(), job.seed);
      }
    };
    if (fs::exists(checkpoint)) {
      loadCheckpoint(checkpoint, job, sim, st);
      if (st.settled) {
        makeRecorder();
        h5::File f(checkpoint, h5::File::Mode::ReadOnly);
        rec->load(f, "/reference");
        if (coverage && f.exists(kCoverageGroup + std::string("/step"))) coverage->load(f, kCoverageGroup);
      }
      spdlog::info("resumed from {} at t = {:.4f} s, {} frames kept", checkpoint, sim.time(), st.framesWritten);
    }

    const double chamberTop = sim.apparatus().upperCorner().y();
    // The phases weighted by their expected cost (jobs/DatabaseProgress.hpp): the fraction grows about
    // linearly in wall time from the filling on, so the ETA of its first minute holds for the rest.
    const DatabaseProgress weights(plan, scene.dem.settle_time, parcelsForBedMass(scene), sim.fillFallSteps(),
                                   sim.grid().cellCount(), sim.hasGas());
    auto fraction = [&] { return st.settled ? weights.coupled(sim.demStep() - st.settledStep) : 0.0; };
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count(); };
    ProgressReporter progress(options.progressJson, options.progressInterval);
    progress.setPriorWallTime(st.wallTime + elapsed());
    progress.setStartFraction(fraction());
    auto save = [&] {
      JobState now = st;
      now.wallTime = st.wallTime + elapsed();
      const ForcedExitDeferral keepTheCheckpoint;
      saveCheckpoint(checkpoint, job, sim, now, rec.get(), coverage.get());
    };
    auto cancelled = [&](const std::string& where) {
      save();
      throw Cancelled("stopped " + where + " at t = " + std::to_string(sim.time()) + " s; checkpoint " + checkpoint);
    };

    if (!st.settled) {
      progress.setPhase("fill");
      progress.setPhaseFraction(0.0);
      progress.report(0.0, sim.time(), true);
      // A stop request during the filling ends the job without a checkpoint (Cancelled, exit 130): a
      // half-filled bed is no state to resume from, and the filling is redone from the seed. The
      // progress comes before every DEM step (a large bed fills for hours).
      auto phaseOf = [](FillStage stage) { return stage == FillStage::Inserting ? "fill" : "settle"; };
      st.fill = sim.fillAndSettle([] { return cancellationRequested(); },
                                  [&](FillStage stage) { progress.setPhase(phaseOf(stage)); },
                                  [&](FillStage stage, double f) {
                                    progress.setPhase(phaseOf(stage));
                                    progress.setPhaseFraction(f);
                                    progress.report(stage == FillStage::Inserting ? weights.fill(f) : weights.settle(f),
                                                     sim.dem().time());
                                  });
      st.settled = true;
      st.settledStep = sim.demStep();
      makeRecorder();
      FieldDatabaseWriterOptions writeOptions;
      writeOptions.velocitySpread = TracerEffectRegistry::needsVelocitySpread(scene.effects);
      {
        const ForcedExitDeferral keepTheDatabaseReadable;
        writer = std::make_unique<FieldDatabaseWriter>(databasePath, sim.grid(), fluid, plan.dtRec(),
                                                       scene.source_json, writeOptions);
      }
      progress.setPhaseFraction(1.0);
      progress.report(fraction(), sim.time(), true);
      if (cancellationRequested() || options.stopAfterSteps == 0) cancelled("after settling");
      // The filling is the longest stretch without one (an hour on the ProCell bed): keep it at once.
      save();
    } else {
      const ForcedExitDeferral keepTheDatabaseReadable;
      writer = FieldDatabaseWriter::reopen(databasePath, sim.grid(), int(st.framesWritten));
    }

    const std::int64_t checkpointEvery = std::max<std::int64_t>(1, std::llround(job.checkpoint_interval / plan.dtDem));
    std::int64_t lastCheckpoint = sim.demStep();
    const std::int64_t firstCouplingStep = st.couplingSteps;
    const std::int64_t totalSamples = plan.totalSamples();
    while (true) {
      // Events at the current instant first: a checkpoint taken after a step resumes here.
      const std::int64_t offset = sim.demStep() - st.settledStep;
      progress.setPhase(coupledPhase(plan, offset));
      if (st.framesWritten < plan.frames && offset == plan.frameOffset(st.framesWritten)) {
        const FieldFrame frame = sampleFrame(sim, fluid, writer->writesVelocitySpread());
        const ForcedExitDeferral keepTheDatabaseReadable;
        writer->append(frame);
        ++st.framesWritten;
      }
      if (rec->samples() < totalSamples && offset == plan.sampleOffset(rec->samples())) {
        // The reference coverage steps from every sample of the reference period to the next.
        if (coverage && rec->samples() >= plan.sampledSamples()) {
          const DemParticles& parcels = sim.dem().particles();
          coverage->step(parcels.x, parcels.id, std::make_shared<const FieldFrame>(sampleFrame(sim, fluid, false)));
        }
        rec->record(sim.particleVelocity(), sim.pressureDrop(), sim.dem().particles());
        const DemParticles& p = sim.dem().particles();
        st.reachedTop.resize(p.size(), 0);
        for (std::size_t i = 0; i < p.size(); ++i) {
          const double top = p.x[i].y() + p.radius[i];
          if (top > st.highestParcelTop) st.highestParcelTop = top, st.highestParcelTime = sim.time();
          if (top >= chamberTop - 2.0 * p.radius[i]) st.reachedTop[i] = 1;
        }
      }
      if (st.framesWritten >= plan.frames && rec->samples() >= totalSamples) break;
      std::int64_t next = plan.sampleOffset(rec->samples());
      if (st.framesWritten < plan.frames) next = std::min(next, plan.frameOffset(st.framesWritten));
      if (offset > next) {
        throw RunError("database job: the clock passed a sampling instant (DEM step " +
                       std::to_string(st.settledStep + next) + ")");
      }
      if (sim.hasGas()) sim.setFlowFactor(plan.flowFactor(offset));
      try {
        sim.step(st.settledStep + next);
      } catch (const RunError& e) {  // a failed step keeps the last checkpoint: say which
        throw RunError(std::string(e.what()) + "; the checkpoint of t = " +
                       std::to_string(double(lastCheckpoint) * plan.dtDem) + " s is kept in " + checkpoint);
      }
      ++st.couplingSteps;
      const bool stopForTest =
          options.stopAfterSteps >= 0 && st.couplingSteps - firstCouplingStep >= options.stopAfterSteps;
      if (cancellationRequested() || stopForTest) {
        cancelled("in the " + progress.phase() + " phase at coupling step " + std::to_string(st.couplingSteps));
      }
      if (sim.demStep() - lastCheckpoint >= checkpointEvery) {
        save();
        lastCheckpoint = sim.demStep();
      }
      const std::int64_t reached = sim.demStep() - st.settledStep;
      progress.setPhase(coupledPhase(plan, reached));
      progress.setPhaseFraction(coupledPhaseFraction(plan, reached));
      progress.report(fraction(), sim.time());
    }
    progress.setPhase("results");
    progress.report(1.0, sim.time(), true);
    {
      const ForcedExitDeferral keepTheDatabaseReadable;
      writer->close();
      h5::File db(databasePath, h5::File::Mode::ReadWrite);
      rec->write(db);
      if (coverage) coverage->write(db);
      db.flush();
    }
    xdmf::writeSidecar(databasePath, xdmfGrid(sim.grid()), {},
                       xdmf::FrameSeries{"/frames", st.framesWritten, plan.dtRec()});

    const double wall = st.wallTime + elapsed();
    const std::size_t parcels = sim.dem().particles().size();
    nlohmann::json summary = {{"kind", job.kind},
                              {"status", "succeeded"},
                              {"seed", job.seed},
                              {"steps", sim.demStep()},
                              {"coupling_steps", st.couplingSteps},
                              {"sim_time_s", sim.time()},
                              {"effects", cfdDemEffects(scene)},
                              {"gas", sim.hasGas()},
                              {"frames", st.framesWritten},
                              {"dt_rec", plan.dtRec()},
                              {"dt_dem", plan.dtDem},
                              {"particles", parcels},
                              {"particles_per_parcel", rec->particlesPerParcel()},
                              {"database", "database.h5"}};
    summary["phases"] = {{"fill_s", st.fill.fill_time},
                         {"settle_s", st.fill.settle_time},
                         {"settled", st.fill.settled},
                         {"ramp_s", double(plan.rampSteps) * plan.dtDem},
                         {"warmup_s", double(plan.warmupSteps) * plan.dtDem},
                         {"sample_s", double(plan.frames) * plan.dtRec()},
                         {"reference_s", double(plan.referenceSamples) * plan.sampleDt()},
                         {"sampling_start_s", double(st.settledStep + plan.frameOffset(0)) * plan.dtDem}};
    summary.update(rec->summary(plan.dtRec(), scene.outputs.residence_time_bins));
    summary["reference_coverage"] = coverage ? coverage->summary() : nlohmann::json();
    // Blow-out: the DEM keeps parcels in with a wall at the outlet, so report how close they came. A
    // parcel that reached the top between two samples (1 / probe_rate apart) would have had to cover
    // the gap in that time.
    const std::int64_t nearTop = std::count(st.reachedTop.begin(), st.reachedTop.end(), std::int64_t(1));
    summary["blow_out"] = {{"highest_parcel_top_m", st.highestParcelTop},
                           {"highest_parcel_time_s", st.highestParcelTime},
                           {"chamber_top_m", chamberTop},
                           {"sample_interval_s", plan.sampleDt()},
                           {"speed_to_reach_top_m_per_s", (chamberTop - st.highestParcelTop) / plan.sampleDt()},
                           {"parcels_reaching_top", nearTop},
                           {"fraction_reaching_top", double(nearTop) / double(std::max<std::size_t>(1, parcels))}};
    try {
      writeResultAndFigures(scene, databasePath, options.outDir, *rec, summary, [] { return cancellationRequested(); });
    } catch (const Cancelled&) {
      // The run is complete: a checkpoint of its end leaves a resume only the results to write.
      cancelled("while writing the results");
    }
    // Wall time and rates describe this machine, not the physics: the only keys allowed to differ
    // between otherwise bit-identical runs.
    summary["wall_time_s"] = wall;
    summary["parcel_steps_per_s"] = wall > 0.0 ? double(parcels) * double(sim.demStep()) / wall : 0.0;
    fs::remove(checkpoint);
    return summary;
  }

 private:
  static void saveCheckpoint(const std::string& path, const JobSpec& job, const CfdDemSimulation& sim,
                             const JobState& st, const ReferenceRecorder* rec, const ReferenceCoverage* coverage) {
    const std::string tmp = path + ".tmp";
    {
      h5::File f(tmp, h5::File::Mode::Create);
      f.writeString("/job/scene", job.scene.source_json);
      f.write("/job/seed", std::vector<std::int64_t>{std::int64_t(job.seed)});
      f.write("/job/counters", std::vector<std::int64_t>{st.settled, st.settledStep, st.framesWritten,
                                                         st.couplingSteps, st.fill.inserted, st.fill.batches,
                                                         st.fill.settled});
      f.write("/job/times", std::vector<double>{st.wallTime, st.fill.fill_time, st.fill.settle_time,
                                                st.fill.kinetic_energy});
      f.write("/job/highest_parcel_top", std::vector<double>{st.highestParcelTop, st.highestParcelTime});
      f.write("/job/reached_top", st.reachedTop);
      sim.saveState(f, "/simulation");
      if (rec) rec->save(f, "/reference");
      if (coverage) coverage->save(f, kCoverageGroup);
      f.flush();
    }
    fs::rename(tmp, path);
  }

  static void loadCheckpoint(const std::string& path, const JobSpec& job, CfdDemSimulation& sim, JobState& st) {
    h5::File f(path, h5::File::Mode::ReadOnly);
    if (f.readString("/job/scene") != job.scene.source_json ||
        f.readInt64s("/job/seed").at(0) != std::int64_t(job.seed)) {
      throw InputError(path, "/job", "the checkpoint belongs to another scene or seed; use a new output directory");
    }
    const auto c = f.readInt64s("/job/counters");
    const auto t = f.readDoubles("/job/times");
    st.settled = c.at(0) != 0;
    st.settledStep = c.at(1);
    st.framesWritten = c.at(2);
    st.couplingSteps = c.at(3);
    st.fill.inserted = long(c.at(4));
    st.fill.batches = int(c.at(5));
    st.fill.settled = c.at(6) != 0;
    st.wallTime = t.at(0);
    st.fill.fill_time = t.at(1);
    st.fill.settle_time = t.at(2);
    st.fill.kinetic_energy = t.at(3);
    if (f.exists("/job/highest_parcel_top")) {
      const auto h = f.readDoubles("/job/highest_parcel_top");
      st.highestParcelTop = h.at(0);
      st.highestParcelTime = h.size() > 1 ? h[1] : 0.0;
      if (f.exists("/job/reached_top")) st.reachedTop = f.readInt64s("/job/reached_top");
    }
    sim.loadState(f, "/simulation");
  }

  /// result.h5 and the figures; rcfd::Cancelled as soon as `stopRequested` says so.
  static void writeResultAndFigures(const Scene& scene, const std::string& databasePath, const std::string& outDir,
                                    const ReferenceRecorder& rec, nlohmann::json& summary,
                                    const std::function<bool()>& stopRequested) {
    auto db = FieldDatabase::open(databasePath, FrameStorage{kFigureCacheBytes});
    const std::vector<double> mean = analysis::meanAlphaP(*db, stopRequested);
    nlohmann::json probes = nlohmann::json::array();
    for (const auto& p : scene.probes) {
      probes.push_back({{"name", p.name}, {"alpha_p_mean", mean[std::size_t(db->grid().flatIndexOf(p.position))]}});
    }
    summary["probes"] = probes;
    {
      const std::string tmp = outDir + "/result.h5.tmp";
      h5::File out(tmp, h5::File::Mode::Create);
      out.writeString("/scene", scene.source_json);
      const CartesianGrid& g = db->grid();
      out.write("/fields/alpha_p_mean", mean, {hsize_t(g.shape[2]), hsize_t(g.shape[1]), hsize_t(g.shape[0])});
      out.setAttribute("/fields/alpha_p_mean", "frames", std::int64_t(db->frameCount()));
      out.flush();
    }
    fs::rename(outDir + "/result.h5.tmp", outDir + "/result.h5");
    xdmf::writeSidecar(outDir + "/result.h5", xdmfGrid(db->grid()));
    if (stopRequested()) throw Cancelled("stopped before drawing the figures");
    if (scene.outputs.svg) {
      analysis::PressureDropSeries dp{rec.pressureDrop(), rec.dt(), 0.0, std::nullopt};
      const auto& f = summary["pressure_drop"]["dominant_frequency_hz"];
      if (f.is_number()) dp.dominantFrequency = f.get<double>();
      summary["figures"] = analysis::writeDatabaseFigures(scene, *db, dp, outDir, stopRequested);
    }
  }
};

const bool registered = JobRunnerRegistry::add("database", "CFD-DEM sampled into a field database",
                                               [] { return std::make_unique<DatabaseJob>(); });

}  // namespace
}  // namespace rcfd
