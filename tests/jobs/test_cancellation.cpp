// Cancelling rcfd-solve in every phase class of every job kind (issue 35, item 3): the real binary runs
// a job with --progress-json on a scene sized so the phase lasts well over 5 s, the test waits until
// the progress names the phase, sends SIGTERM (what the server's cancel sends) and expects exit 130
// within 5 s, by the phase's own stop (its message, not the watchdog's). Where the phase checkpoints,
// the same command then resumes from where it stopped.
//
// Phase classes: the DEM fill (polled every DEM step, nothing kept), the coupled run (ramp, warm-up,
// sampling and reference share one loop: polled every coupling step, checkpointed), the recurrence
// setup (reading the database, the matrix: polled every frame and tile, nothing kept) and the tracer
// runs (polled every step, checkpointed). The results phases look between their parts and are short
// next to the phases above; the watchdog that bounds every phase is tested in-process at the end.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "SolveChild.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "jobs/Cancellation.hpp"
#include "scene/SceneLoader.hpp"

using nlohmann::json;
namespace fs = std::filesystem;
using rcfd::test::SolveChild;

namespace {

/// What the server's cancel promises, from SIGTERM to the solver's exit [s].
constexpr double kStopWithin = 5.0;
/// Longest wait for a phase to start (a loaded machine) [s].
constexpr double kPhaseTimeout = 60.0;

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("rcfd-test-cancel-" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

void writeJson(const fs::path& path, const json& document) { std::ofstream(path) << document.dump(2); }

std::vector<std::string> runArgs(const fs::path& job, const fs::path& out) {
  return {"run", job.string(), "--out", out.string(), "--progress-json"};
}

/// Sends SIGTERM and checks the exit: code 130 within kStopWithin, and the phase's own message.
void expectCancelledWithin(SolveChild& solver, const std::string& message) {
  const double took = solver.signalAndWait(SIGTERM, 30.0);
  testing::Test::RecordProperty("seconds_to_exit", std::to_string(took));
  EXPECT_LT(took, kStopWithin) << solver.stderrText();
  EXPECT_EQ(solver.exitCode(), rcfd::exit_code::cancelled) << solver.stderrText();
  EXPECT_NE(solver.stderrText().find(message), std::string::npos) << solver.stderrText();
  EXPECT_EQ(solver.stderrText().find("no stopping point"), std::string::npos) << solver.stderrText();
}

/// A DEM-only box scene (no `gas`); `bedMass` [kg] of `diameter` [m] parcels.
json demScene(const std::string& name, const std::vector<double>& size, double diameter, double bedMass,
              double timeStep, double sampleDuration) {
  return {{"name", name},
          {"apparatus", {{"type", "box"}, {"size", size}}},
          {"grid", {{"cell_size", 0.01}}},
          {"gas", json::object()},
          {"particles", {{"diameter", diameter}, {"density", 1040.0}}},
          {"process", {{"bed_mass", bedMass}}},
          {"dem",
           {{"time_step", timeStep}, {"coupling_interval", 5}, {"settle_time", 0.15}, {"ramp_time", 0.0},
            {"warmup", 0.01}, {"sample_rate", 200}, {"probe_rate", 1000}, {"sample_duration", sampleDuration},
            {"reference_duration", 0.03}}},
          {"probes", {{{"name", "bed"}, {"position", {0.0025, 0.0025, 0.0075}}}}},
          {"effects", {"rolling_friction"}}};
}

/// The tracer scene of the spray and calibration jobs on a box database with cells of `cell` [m].
json tracerScene(double cell, long tracers) {
  return {{"name", "cancel-tracers"},
          {"apparatus", {{"type", "box"}, {"size", {0.1, 0.15, 0.04}}, {"outlet_top", true}}},
          {"grid", {{"cell_size", cell}}},
          {"gas", json::object()},
          {"particles", json::object()},
          {"process", {{"bed_mass", 0.3}}},
          {"rcfd", {{"dt", 0.005}, {"tracers", tracers}, {"d0", 5e-4}, {"path", {{"type", "paper"}}}}},
          {"spray",
           {{"nozzle_position", {0.0, 0.005, 0.02}},
            {"nozzle_diameter", 0.002},
            {"parcels_per_s", 4000},
            {"spray_zone", {{"apex", {0.0, 0.005, 0.02}}, {"y_min", 0.01}, {"y_max", 0.08}}}}},
          {"probes", {{{"name", "centre"}, {"position", {0.0, 0.05, 0.02}}}}},
          {"effects", {"transport", "walls", "fluctuation", "free_flight", "tracer_volume_fraction", "probes",
                       "residence_time"}}};
}

/// A database of `frames` frames on the grid of `scene`: a spout swaying left and right over a bed, so
/// frames differ. alpha_P takes few values and the velocities are smooth, so the file compresses well.
void writeSwayingDatabase(const json& scene, const fs::path& path, int frames) {
  const rcfd::Scene s = rcfd::loadScene(scene, "test scene");
  const rcfd::Apparatus box(s.apparatus);
  const auto grid = rcfd::makeGrid(box, s.grid);
  const auto open = rcfd::openFractions(box, grid);
  rcfd::FieldDatabaseWriterOptions compact;
  compact.deflateLevel = 1;
  compact.shuffle = true;
  rcfd::writeAnalyticDatabase(
      path.string(), grid, std::vector<float>(open.begin(), open.end()), s.rcfd.dt, frames,
      [&](int, double t, rcfd::FieldFrame& f) {
        const double centre = 0.02 * std::sin(2.0 * M_PI * t / 0.25);
        for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
          const auto ijk = grid.cellIjk(c);
          const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
          const bool spout = std::abs(p.x() - centre) < 0.015 && p.y() < 0.1;
          const auto i = std::size_t(c);
          f.alpha_p[i] = float(spout ? 0.125 : (p.y() < 0.07 ? 0.5 : 0.0));
          f.u_p[3 * i + 1] = float(spout ? 1.0 : -0.25);
          f.u_g[3 * i + 1] = float(spout ? 6.0 : 1.0);
        }
      },
      scene.dump(), compact);
}

/// The step a resumed tracer run continues from, from its log line "... resumed ... step N ..."; -1
/// when there is none.
long resumedStep(const std::string& log) {
  std::smatch m;
  if (!std::regex_search(log, m, std::regex("resumed[^\\n]*?step ([0-9]+)"))) return -1;
  return std::stol(m[1]);
}

}  // namespace

// --- database job ---

// A large bed (23,000 parcels of 2 mm) at dt_DEM = 1 us: the fill runs for minutes, and one
// millisecond of simulated time (how often it used to look at the request) takes over 10 s.
TEST(CancelDatabaseJob, DuringTheFillStopsWithoutACheckpoint) {
  const fs::path dir = scratch("fill");
  writeJson(dir / "job.json", {{"kind", "database"},
                               {"scene", demScene("cancel-fill", {0.1, 0.3, 0.05}, 0.002, 0.1, 1e-6, 0.05)},
                               {"seed", 3}});
  SolveChild solver(runArgs(dir / "job.json", dir / "out"), dir / "stderr.txt");
  // Some DEM steps in, so the batch is falling.
  const auto falling = [](const json& p) { return p.value("phase", "") == "fill" && p.at("sim_time") > 0.0; };
  ASSERT_FALSE(solver.waitForProgress(falling, kPhaseTimeout).is_null()) << solver.stderrText();
  expectCancelledWithin(solver, "stopped while filling and settling the bed");
  EXPECT_FALSE(fs::exists(dir / "out" / "checkpoint.h5"));
  fs::remove_all(dir);
}

// 340 parcels sampled for 4 s of simulated time: the sampling phase lasts over 10 s.
TEST(CancelDatabaseJob, DuringTheSamplingCheckpointsAndTheSameCommandResumes) {
  const fs::path dir = scratch("sample");
  writeJson(dir / "job.json", {{"kind", "database"},
                               {"scene", demScene("cancel-sample", {0.04, 0.1, 0.02}, 0.003, 0.005, 2e-5, 4.0)},
                               {"seed", 3},
                               {"checkpoint_interval", 100.0}});
  double stoppedAt = 0.0;
  {
    SolveChild solver(runArgs(dir / "job.json", dir / "out"), dir / "stderr.txt");
    const json sampling = solver.waitForProgress(
        [](const json& p) { return p.value("phase", "") == "sample" && p.at("fraction") > 0.1; }, kPhaseTimeout);
    ASSERT_FALSE(sampling.is_null()) << solver.stderrText();
    stoppedAt = sampling.at("sim_time");
    expectCancelledWithin(solver, "stopped in the sample phase");
    ASSERT_TRUE(fs::exists(dir / "out" / "checkpoint.h5"));
  }
  // The same command goes on from the checkpoint (frames and all), not from the fill.
  SolveChild resumed(runArgs(dir / "job.json", dir / "out"), dir / "stderr-resumed.txt");
  const json first = resumed.waitForProgress([](const json&) { return true; }, kPhaseTimeout);
  ASSERT_FALSE(first.is_null()) << resumed.stderrText();
  EXPECT_EQ(first.value("phase", ""), "sample") << first.dump();
  EXPECT_GE(first.at("sim_time").get<double>(), stoppedAt);
  EXPECT_NE(resumed.stderrText().find("resumed from"), std::string::npos) << resumed.stderrText();
  expectCancelledWithin(resumed, "stopped in the sample phase");
  fs::remove_all(dir);
}

// The results phase reads every frame back (the time average, the figures): 400 frames of 45,000 cells,
// about half a second here. It polls before every frame and keeps the finished run in a checkpoint, so
// the same command then only writes the results. Its length is that of reading the file, far below
// 5 s at any size a test can write, so the signal may come too late: then the test is skipped.
TEST(CancelDatabaseJob, WhileWritingTheResultsCheckpointsTheRunAndTheSameCommandOnlyWritesThem) {
  const fs::path dir = scratch("results");
  json scene = demScene("cancel-results", {0.1, 0.2, 0.1}, 0.003, 0.005, 2e-5, 0.4);
  scene["grid"]["cell_size"] = 0.0035;
  scene["dem"]["sample_rate"] = 1000;
  writeJson(dir / "job.json", {{"kind", "database"}, {"scene", scene}, {"seed", 3}, {"checkpoint_interval", 100.0}});
  {
    SolveChild solver(runArgs(dir / "job.json", dir / "out"), dir / "stderr.txt");
    ASSERT_FALSE(solver.waitForPhase("results", kPhaseTimeout).is_null()) << solver.stderrText();
    const double took = solver.signalAndWait(SIGTERM, 30.0);
    if (solver.exitCode() == 0) GTEST_SKIP() << "the results were written before the signal arrived";
    EXPECT_LT(took, kStopWithin);
    EXPECT_EQ(solver.exitCode(), rcfd::exit_code::cancelled) << solver.stderrText();
    EXPECT_NE(solver.stderrText().find("stopped while writing the results"), std::string::npos) << solver.stderrText();
    ASSERT_TRUE(fs::exists(dir / "out" / "checkpoint.h5"));
    EXPECT_FALSE(fs::exists(dir / "out" / "summary.json"));
  }
  SolveChild resumed(runArgs(dir / "job.json", dir / "out"), dir / "stderr-resumed.txt");
  ASSERT_EQ(resumed.wait(kPhaseTimeout), 0) << resumed.stderrText();
  // No DEM step again: the progress goes straight to the results.
  ASSERT_FALSE(resumed.progress().empty());
  for (const auto& p : resumed.progress()) EXPECT_EQ(p.value("phase", ""), "results") << p.dump();
  const json summary = json::parse(std::ifstream(dir / "out" / "summary.json"));
  EXPECT_EQ(summary.at("frames"), 400);
  EXPECT_FALSE(fs::exists(dir / "out" / "checkpoint.h5"));
  fs::remove_all(dir);
}

// --- the recurrence setup of calibration and spray jobs ---

// 5000 frames of 4800 cells: reading them and computing their recurrence matrix takes well over 5 s.
// The database is shared by the calibration and the spray job; neither may leave a matrix in it.
class CancelRecurrenceSetup : public testing::Test {
 protected:
  static constexpr int kFrames = 5000;
  static constexpr double kCell = 0.005;
  static void SetUpTestSuite() {
    dir_ = new fs::path(scratch("recurrence"));
    writeSwayingDatabase(tracerScene(kCell, 1000), *dir_ / "long.h5", kFrames);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    dir_ = nullptr;
  }
  static void expectNoStoredMatrix() {
    rcfd::h5::File db((*dir_ / "long.h5").string(), rcfd::h5::File::Mode::ReadOnly);
    EXPECT_FALSE(db.exists("/recurrence/matrix"));
  }
  static fs::path* dir_;
};
fs::path* CancelRecurrenceSetup::dir_ = nullptr;

TEST_F(CancelRecurrenceSetup, OfACalibrationJobStopsAndLeavesTheDatabaseAsItWas) {
  // Frames through the cache: the phase is the matrix itself, its frames read as its tiles need them.
  json scene = tracerScene(kCell, 1000);
  scene["rcfd"]["frame_cache_bytes"] = 64 << 20;
  writeJson(*dir_ / "calibration.json", {{"kind", "calibration"},
                                         {"scene", scene},
                                         {"database", (*dir_ / "long.h5").string()},
                                         {"duration", 1.0},
                                         {"discard", 0.2},
                                         {"seed", 5},
                                         {"d0_values", {0.0, 1e-3}}});
  SolveChild solver(runArgs(*dir_ / "calibration.json", *dir_ / "calibration"), *dir_ / "calibration.txt");
  ASSERT_FALSE(solver.waitForPhase("recurrence", kPhaseTimeout).is_null()) << solver.stderrText();
  expectCancelledWithin(solver, "stopped while computing the recurrence matrix");
  expectNoStoredMatrix();
  EXPECT_FALSE(fs::exists(*dir_ / "calibration" / "runs"));
}

TEST_F(CancelRecurrenceSetup, OfASprayJobStopsAndLeavesTheDatabaseAsItWas) {
  // All frames in RAM first (frame_cache_bytes 0, the default): the stop comes while they are read
  // or, on a fast machine, in the matrix after them.
  writeJson(*dir_ / "spray.json", {{"kind", "spray"},
                                   {"scene", tracerScene(kCell, 1000)},
                                   {"database", (*dir_ / "long.h5").string()},
                                   {"duration", 1.0},
                                   {"seed", 5}});
  SolveChild solver(runArgs(*dir_ / "spray.json", *dir_ / "spray"), *dir_ / "spray.txt");
  ASSERT_FALSE(solver.waitForPhase("recurrence", kPhaseTimeout).is_null()) << solver.stderrText();
  expectCancelledWithin(solver, "cancelled: stopped while");
  const std::string log = solver.stderrText();
  EXPECT_TRUE(log.find("into memory") != std::string::npos || log.find("recurrence matrix") != std::string::npos)
      << log;
  expectNoStoredMatrix();
}

// --- the tracer runs of calibration and spray jobs ---

// A small database (its matrix takes milliseconds) and runs of 1000 s of simulated time: the runs
// phase never ends by itself within the test.
class CancelTracerRuns : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratch(testing::UnitTest::GetInstance()->current_test_info()->name());
    writeSwayingDatabase(tracerScene(0.01, 2000), dir_ / "db.h5", 40);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(CancelTracerRuns, OfACalibrationJobCheckpointEveryRunAndTheSameCommandResumes) {
  writeJson(dir_ / "job.json", {{"kind", "calibration"},
                                {"scene", tracerScene(0.01, 2000)},
                                {"database", (dir_ / "db.h5").string()},
                                {"duration", 1000.0},
                                {"discard", 0.2},
                                {"seed", 5},
                                {"checkpoint_interval", 1000.0},
                                {"d0_values", {0.0, 1e-3}}});
  {
    SolveChild solver(runArgs(dir_ / "job.json", dir_ / "out"), dir_ / "stderr.txt");
    const auto running = [](const json& p) { return p.value("phase", "") == "runs" && p.value("phase_fraction", 0.0) > 0.0; };
    ASSERT_FALSE(solver.waitForProgress(running, kPhaseTimeout).is_null()) << solver.stderrText();
    expectCancelledWithin(solver, "calibration stopped in the runs phase");
    EXPECT_TRUE(fs::exists(dir_ / "out" / "runs" / "d0_0" / "checkpoint.h5"));
    EXPECT_TRUE(fs::exists(dir_ / "out" / "runs" / "d0_1" / "checkpoint.h5"));
  }
  SolveChild resumed(runArgs(dir_ / "job.json", dir_ / "out"), dir_ / "stderr-resumed.txt");
  const json first = resumed.waitForPhase("runs", kPhaseTimeout);
  ASSERT_FALSE(first.is_null()) << resumed.stderrText();
  // The steps of the checkpoints are counted before the runs start; each run's "resumed at step N" is
  // logged before its first step, so once the runs moved on from there it is in the log.
  EXPECT_GT(first.at("phase_fraction").get<double>(), 0.0) << first.dump();
  const double from = first.at("phase_fraction");
  ASSERT_FALSE(resumed.waitForProgress([&](const json& p) { return p.value("phase_fraction", 0.0) > from; },
                                       kPhaseTimeout).is_null());
  EXPECT_GT(resumedStep(resumed.stderrText()), 0) << resumed.stderrText();
  expectCancelledWithin(resumed, "calibration stopped in the runs phase");
}

TEST_F(CancelTracerRuns, OfASprayJobCheckpointsAndTheSameCommandResumes) {
  writeJson(dir_ / "job.json", {{"kind", "spray"},
                                {"scene", tracerScene(0.01, 2000)},
                                {"database", (dir_ / "db.h5").string()},
                                {"duration", 1000.0},
                                {"seed", 5},
                                {"checkpoint_interval", 1000.0}});
  double stoppedAt = 0.0;
  {
    SolveChild solver(runArgs(dir_ / "job.json", dir_ / "out"), dir_ / "stderr.txt");
    const json running = solver.waitForProgress(
        [](const json& p) { return p.value("phase", "") == "run" && p.value("phase_fraction", 0.0) > 0.0; }, kPhaseTimeout);
    ASSERT_FALSE(running.is_null()) << solver.stderrText();
    stoppedAt = running.at("sim_time");
    expectCancelledWithin(solver, "stopped in the run phase");
    EXPECT_TRUE(fs::exists(dir_ / "out" / "checkpoint.h5"));
  }
  SolveChild resumed(runArgs(dir_ / "job.json", dir_ / "out"), dir_ / "stderr-resumed.txt");
  const json first = resumed.waitForPhase("run", kPhaseTimeout);
  ASSERT_FALSE(first.is_null()) << resumed.stderrText();
  EXPECT_GE(first.at("sim_time").get<double>(), stoppedAt);
  EXPECT_GT(resumedStep(resumed.stderrText()), 0) << resumed.stderrText();
  expectCancelledWithin(resumed, "stopped in the run phase");
}

TEST_F(CancelTracerRuns, OfAnEnsembleCheckpointsEveryRunningMemberAndTheSameCommandResumes) {
  writeJson(dir_ / "job.json", {{"kind", "spray"},
                                {"scene", tracerScene(0.01, 2000)},
                                {"database", (dir_ / "db.h5").string()},
                                {"duration", 1000.0},
                                {"seed", 5},
                                {"checkpoint_interval", 1000.0},
                                {"ensemble", 3}});
  auto args = runArgs(dir_ / "job.json", dir_ / "out");
  args.insert(args.end(), {"--threads", "2"});  // two members at a time
  {
    SolveChild solver(args, dir_ / "stderr.txt");
    const json running = solver.waitForProgress(
        [](const json& p) { return p.value("phase", "") == "run" && p.value("phase_fraction", 0.0) > 0.0; }, kPhaseTimeout);
    ASSERT_FALSE(running.is_null()) << solver.stderrText();
    expectCancelledWithin(solver, "ensemble stopped in the run phase");
    EXPECT_TRUE(fs::exists(dir_ / "out" / "members" / "00" / "checkpoint.h5"));
    EXPECT_TRUE(fs::exists(dir_ / "out" / "members" / "01" / "checkpoint.h5"));
    EXPECT_FALSE(fs::exists(dir_ / "out" / "members" / "02"));
  }
  // The run phase starts from the members' checkpoints; each member logs "resumed at step N" before
  // its first step, so by a report beyond the first every running member has.
  SolveChild resumed(args, dir_ / "stderr-resumed.txt");
  const json first = resumed.waitForPhase("run", kPhaseTimeout);
  ASSERT_FALSE(first.is_null()) << resumed.stderrText();
  EXPECT_GT(first.at("fraction").get<double>(), 0.0);
  const double from = first.at("fraction");
  ASSERT_FALSE(resumed.waitForProgress([&](const json& p) { return p.at("fraction") > from; }, kPhaseTimeout).is_null());
  EXPECT_GT(resumedStep(resumed.stderrText()), 0) << resumed.stderrText();
  expectCancelledWithin(resumed, "ensemble stopped in the run phase");
}

// --- the watchdog: the bound for the steps no phase can look inside ---

// In a child process each (a death test): the watchdog ends the process it runs in.
TEST(CancellationWatchdog, EndsAProcessThatDoesNotStopByTheDeadlineButLetsADeferralFinish) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  // A loop that never polls stands for one long step; the deferral for a checkpoint being written.
  EXPECT_EXIT(
      {
        rcfd::startCancellationWatchdog(0.3);
        rcfd::requestCancellation();
        {
          const rcfd::ForcedExitDeferral writing;
          std::this_thread::sleep_for(std::chrono::milliseconds(600));
          std::fprintf(stderr, "the deferred write ended\n");
        }
        for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      },
      testing::ExitedWithCode(rcfd::exit_code::cancelled), "the deferred write ended\n.*no stopping point");
  // Without a request it does nothing.
  EXPECT_EXIT(
      {
        rcfd::startCancellationWatchdog(0.05);
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        std::exit(0);
      },
      testing::ExitedWithCode(0), "");
}
