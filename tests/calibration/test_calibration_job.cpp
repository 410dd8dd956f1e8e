// The calibration job end to end on an analytic box database: the tracers start over-packed in one
// half (frame 0), all later frames are uniform, so relaxation (D0 > 0) is what brings the tracer
// alpha_P to the recurrence alpha_P. Checks the penalty ordering, the summary, determinism, thread
// independence, missing and present reference statistics, and resume after an interruption.
#include <gtest/gtest.h>

#include "../BitIdentical.hpp"

#include <algorithm>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "../tracers/TracerTestSupport.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "core/Errors.hpp"
#include "jobs/JobRunner.hpp"
#include "recurrence/PathFile.hpp"
#include "scene/SceneJson.hpp"

using namespace rcfd;
using namespace rcfd::test;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kDt = 0.005;
constexpr int kFrames = 50;
constexpr std::int64_t kSteps = 300;

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("rcfd-test-calibration-" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

Scene calibrationScene(const fs::path& pathFile) {
  Scene s = boxScene({0.02, 0.02, 0.01}, 0.005, 2000, kDt, {"transport"}, 0.25);
  s.rcfd.path.type = "file";
  s.rcfd.path.file = pathFile.string();
  s.probes = {{"left", Vec3(-0.0075, 0.0075, 0.0025)},
              {"centre", Vec3(0.0025, 0.0125, 0.0075)},
              {"right", Vec3(0.0075, 0.0075, 0.0025)}};
  // A slab-like spray zone around x = 0: a cone with a far-away apex and a narrow half-angle.
  s.spray.spray_zone.apex = Vec3(0.0, -10.0, 0.005);
  s.spray.spray_zone.half_angle_deg = 0.03;
  s.spray.spray_zone.y_min = 0.0;
  s.spray.spray_zone.y_max = 0.02;
  s.outputs.residence_time_bins = 20;
  s.source_json = "{\"test\": \"calibration box\"}";
  return s;
}

/// Writes the database (frame 0: the bed in the left half; then uniform 0.25, at rest) and the path
/// file (frame 0 once, then frames 1..49 cycling) into dir; returns the job.
JobSpec makeJob(const fs::path& dir, std::vector<double> d0 = {0.0, 1e-3, 1e-2}) {
  const fs::path pathFile = dir / "path.txt";
  RecurrencePath path;
  path.frames.push_back(0);
  for (int k = 1; k < kSteps + 10; ++k) path.frames.push_back(1 + (k - 1) % (kFrames - 1));
  writePathFile(pathFile.string(), path);
  JobSpec job;
  job.kind = "calibration";
  job.scene = calibrationScene(pathFile);
  const CartesianGrid grid = gridOf(job.scene);
  Apparatus a(job.scene.apparatus);
  const auto open = openFractions(a, grid);
  writeAnalyticDatabase((dir / "db.h5").string(), grid, std::vector<float>(open.begin(), open.end()), kDt, kFrames,
                        [&](int n, double, FieldFrame& f) {
                          for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
                            const auto ijk = grid.cellIjk(c);
                            f.alpha_p[std::size_t(c)] = n == 0 ? (ijk[0] < 2 ? 0.5f : 0.0f) : 0.25f;
                          }
                        });
  job.database = (dir / "db.h5").string();
  job.duration = double(kSteps) * kDt;
  job.discard = 0.5;
  job.seed = 5;
  job.checkpoint_interval = 0.5;
  job.d0_values = std::move(d0);
  job.source = json::object();
  return job;
}

json run(const JobSpec& job, const fs::path& out, long stopAfter = -1) {
  RunOptions o;
  o.outDir = out.string();
  o.stopAfterSteps = stopAfter;
  return runJob(job, o);
}

json withoutWallTime(json s) {
  s.erase("wall_time_s");
  return s;
}

/// Every numeric dataset of a calibration result.h5 (by name), for bit-for-bit comparisons.
std::vector<std::string> resultDatasets(std::size_t runs) {
  std::vector<std::string> names = {"/calibration/d0", "/calibration/penalty", "/calibration/rms",
                                    "/calibration/field_rms_difference", "/calibration/field_rms_difference_midplane",
                                    "/calibration/holdup_mean", "/calibration/residence_time_mean_s",
                                    "/calibration/residence_time_median_s", "/calibration/rtd_edges",
                                    "/calibration/recurrence/alpha_p_midplane", "/path/frames"};
  for (std::size_t i = 0; i < runs; ++i) {
    const std::string g = "/calibration/runs/d0_" + std::to_string(i);
    for (const char* d : {"/probes/time", "/probes/alpha_p_tracers", "/probes/alpha_p_recurrence", "/holdup/particles",
                          "/residence_time/duration_steps_counts", "/residence_time/density",
                          "/field_average/alpha_p_midplane"}) {
      names.push_back(g + d);
    }
  }
  return names;
}

void expectSameResults(const fs::path& a, const fs::path& b, std::size_t runs) {
  h5::File fa((a / "result.h5").string(), h5::File::Mode::ReadOnly);
  h5::File fb((b / "result.h5").string(), h5::File::Mode::ReadOnly);
  for (const auto& name : resultDatasets(runs)) {
    ASSERT_TRUE(fa.exists(name)) << name;
    ASSERT_TRUE(fb.exists(name)) << name;
    const auto va = fa.readDoubles(name), vb = fb.readDoubles(name);
    ASSERT_EQ(va.size(), vb.size()) << name;
    EXPECT_TRUE(rcfd::test::bitIdentical(va, vb)) << name;
  }
}

void setThreads(int n) {
#ifdef _OPENMP
  omp_set_num_threads(n);
#else
  (void)n;
#endif
}

}  // namespace

TEST(CalibrationJob, RelaxationLowersThePenaltyAndEveryD0IsReported) {
  const fs::path dir = scratch("basic");
  const JobSpec job = makeJob(dir);
  const json s = run(job, dir / "out");
  EXPECT_EQ(s["kind"], "calibration");
  EXPECT_EQ(s["status"], "succeeded");
  // The penalty falls up to the largest D0 of the list: the sweep is extended (x3) up to the D0 at which
  // u_fluc_max binds, 6 pi dt u_fluc_max^2 = 0.0942 m2/s for Eq. (10), and says so.
  const double binding = 6.0 * 3.14159265358979323846 * kDt * 1.0;
  EXPECT_NEAR(s["sweep_extension"]["binding_d0"].get<double>(), binding, 1e-12);
  const json& added = s["sweep_extension"]["added"];
  ASSERT_GE(added.size(), 1u) << s["sweep_extension"].dump();
  EXPECT_NEAR(added[0].get<double>(), 3e-2, 1e-15);
  for (std::size_t k = 1; k < added.size(); ++k) {
    EXPECT_NEAR(added[k].get<double>(), std::min(binding, 3.0 * added[k - 1].get<double>()), 1e-12);
  }
  // It stopped because the optimum now lies inside the sweep, or because the cap binds.
  if (s["sweep_extension"].contains("stopped")) {
    EXPECT_NEAR(added.back().get<double>(), binding, 1e-12);
    EXPECT_NE(s["sweep_extension"]["stopped"].get<std::string>().find("u_fluc_max already binds"), std::string::npos);
  } else {
    EXPECT_FALSE(s["selection"]["at_upper_end"].get<bool>());
    EXPECT_LT(s["selected_d0"].get<double>(), added.back().get<double>());
  }
  const std::size_t runs = 3 + added.size();
  ASSERT_EQ(s["d0"].size(), runs);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(s["d0"][i]["value"].get<double>(), job.d0_values[i]);
    for (const char* key : {"penalty", "holdup_mean", "residence_time_mean_s", "field_rms_difference"}) {
      EXPECT_TRUE(s["d0"][i][key].is_number()) << key;
    }
  }
  const double selected = s["selected_d0"].get<double>();
  std::size_t sel = 0;
  while (sel < runs && s["d0"][sel]["value"].get<double>() != selected) ++sel;
  ASSERT_LT(sel, runs) << "selected_d0 " << selected << " is not one of the values";
  EXPECT_GT(selected, 0.0);
  EXPECT_GT(s["d0"][0]["penalty"].get<double>(), s["d0"][sel]["penalty"].get<double>());
  // Without relaxation the bed keeps its frame-0 shape: the field error is far above the relaxed one.
  EXPECT_GT(s["d0"][0]["field_rms_difference"].get<double>(), 2.0 * s["d0"][sel]["field_rms_difference"].get<double>());
  EXPECT_EQ(s["d0"][0]["stays"].get<long>(), 0) << "nothing moves at D0 = 0";
  EXPECT_GT(s["d0"][2]["stays"].get<long>(), 0);
  EXPECT_TRUE(s["penalty_minimum_d0"].is_number());
  EXPECT_FALSE(s["selection_reason"].get<std::string>().empty());
  EXPECT_EQ(s["effects"].size(), 8u);
  // Outputs: result.h5 datasets, the figures, summary.json on disk.
  h5::File r((dir / "out/result.h5").string(), h5::File::Mode::ReadOnly);
  std::vector<double> all = job.d0_values;
  for (const auto& a : added) all.push_back(a.get<double>());
  EXPECT_EQ(r.readDoubles("/calibration/d0"), all);
  EXPECT_EQ(r.doubleAttribute("/calibration", "selected_d0"), selected);
  EXPECT_EQ(r.shape("/calibration/runs/d0_1/probes/alpha_p_tracers")[1], 3u);
  EXPECT_EQ(r.readDoubles("/calibration/runs/d0_1/holdup/particles").size(), std::size_t(kSteps - 100));
  for (const auto& f : s["figures"]) EXPECT_TRUE(fs::exists(dir / "out" / f.get<std::string>())) << f;
  EXPECT_EQ(s["figures"].size(), 5u);
  EXPECT_TRUE(fs::exists(dir / "out/summary.json"));
}

// A scene that lists directed_relaxation is calibrated with it in place of Eq. (10): D0 is its
// strength, and it relaxes the bed of the left half as Eq. (10) does.
TEST(CalibrationJob, TheRelaxationModelTheSceneListsIsCalibrated) {
  const fs::path dir = scratch("directed");
  JobSpec job = makeJob(dir, {0.0, 1e-3});
  job.scene.effects = {"transport", "directed_relaxation"};
  job.source["extend_sweep"] = false;
  const json s = run(job, dir / "out");
  const auto effects = s["effects"].get<std::vector<std::string>>();
  EXPECT_NE(std::find(effects.begin(), effects.end(), "directed_relaxation"), effects.end());
  EXPECT_EQ(std::find(effects.begin(), effects.end(), "fluctuation"), effects.end());
  EXPECT_GT(s["d0"][0]["field_rms_difference"].get<double>(), 2.0 * s["d0"][1]["field_rms_difference"].get<double>());
}

TEST(CalibrationJob, MissingReferenceIsReportedNotFatal) {
  const fs::path dir = scratch("noref");
  const json s = run(makeJob(dir), dir / "out");
  const json& ref = s["reference"];
  EXPECT_FALSE(ref["available"].get<bool>());
  EXPECT_EQ(ref["missing"], json({"/reference/residence_time/durations_s", "/reference/holdup/particles"}));
  EXPECT_EQ(ref["scores_not_computed"], json({"rtd_ks_distance", "holdup_relative_error"}));
  for (const auto& d : s["d0"]) {
    EXPECT_TRUE(d["rtd_ks_distance"].is_null());
    EXPECT_TRUE(d["holdup_relative_error"].is_null());
  }
  EXPECT_EQ(s["selection"]["residence_times_judged_by"], "mean_relative_tolerance");
  // The field's own holdup is reported without a reference too. After frame 0 the field is 0.25
  // everywhere, and the zone is a vertical cylinder of radius 10 m x tan(0.03 deg) = 5.24 mm about
  // z = 5 mm, 20 mm high, cut by the walls z = 0 and 10 mm: 85.3 mm2 x 20 mm.
  const JobSpec job = makeJob(scratch("noref-geometry"));
  const double r = 10.0 * std::tan(0.03 * 3.14159265358979323846 / 180.0), d = 0.005;
  const double cap = r * r * std::acos(d / r) - d * std::sqrt(r * r - d * d);
  const double zoneVolume = (3.14159265358979323846 * r * r - 2.0 * cap) * 0.02;
  const double particle = 3.14159265358979323846 / 6.0 * std::pow(job.scene.particles.diameter, 3);
  EXPECT_NEAR(ref["recurrence_field_holdup"].get<double>(), 0.25 * zoneVolume / particle, 0.05 * 0.25 * zoneVolume / particle);
  EXPECT_FALSE(ref.contains("recurrence_field_holdup_over_reference"));
}

TEST(CalibrationJob, ReferenceStatisticsAreUsed) {
  // The reference is the D0 = 1e-2 run's own RTD and holdup: that run must score KS = 0 and a zero
  // holdup error, the frozen D0 = 0 run (no stays) no KS distance at all.
  const fs::path dir = scratch("ref");
  JobSpec job = makeJob(dir);
  const json first = run(job, dir / "first");
  std::vector<double> durations, holdup;
  {
    h5::File r((dir / "first/result.h5").string(), h5::File::Mode::ReadOnly);
    const auto counts = r.readInt64s("/calibration/runs/d0_2/residence_time/duration_steps_counts");
    for (std::size_t k = 0; k < counts.size(); ++k)
      for (std::int64_t c = 0; c < counts[k]; ++c) durations.push_back(double(k) * kDt);
    holdup = r.readDoubles("/calibration/runs/d0_2/holdup/particles");
  }
  ASSERT_FALSE(durations.empty());
  {
    h5::File db(job.database, h5::File::Mode::ReadWrite);
    db.write(analysis::reference_layout::durations, durations);
    db.write(analysis::reference_layout::holdup, holdup);
    db.setAttribute(analysis::reference_layout::holdup, "dt", kDt);
  }
  const json s = run(job, dir / "second");
  EXPECT_TRUE(s["reference"]["available"].get<bool>());
  EXPECT_TRUE(s["reference"]["scores_not_computed"].empty());
  EXPECT_EQ(s["selection"]["residence_times_judged_by"], "ks_mean_and_crossing_rate_on_the_tracer_lattice");
  EXPECT_TRUE(s["d0"][0]["rtd_ks_distance"].is_null());
  EXPECT_NEAR(s["d0"][2]["rtd_ks_distance"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(s["d0"][2]["holdup_relative_error"].get<double>(), 0.0, 1e-12);
  ASSERT_TRUE(s["d0"][1]["rtd_ks_distance"].is_number());
  EXPECT_GT(s["d0"][1]["rtd_ks_distance"].get<double>(), 0.0);
  EXPECT_LE(s["d0"][1]["rtd_ks_distance"].get<double>(), 1.0);
  EXPECT_NEAR(s["reference"]["residence_time_mean_s"].get<double>(), s["d0"][2]["residence_time_mean_s"].get<double>(),
              1e-12);
  // The scores not depending on the reference are those of the run without it.
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(s["d0"][i]["penalty"], first["d0"][i]["penalty"]);
}

TEST(CalibrationJob, AReferenceCountedInAnotherSprayZoneIsNotCompared) {
  // The database job counted its stays in the zone of the database's /scene; a job whose scene moved
  // the zone (or clipped it to the apex's line of sight) would compare tracers counted elsewhere.
  const fs::path dir = scratch("zone");
  JobSpec job = makeJob(dir, {0.0, 1e-2});
  auto writeReference = [&](const SprayZoneSpec& zone) {
    h5::File db(job.database, h5::File::Mode::ReadWrite);
    Scene counted = job.scene;
    counted.spray.spray_zone = zone;
    if (db.exists("/scene")) H5Ldelete(db.id(), "/scene", H5P_DEFAULT);
    db.writeString("/scene", sceneToJson(counted).dump());
    for (const char* name : {analysis::reference_layout::durations, analysis::reference_layout::holdup})
      if (db.exists(name)) H5Ldelete(db.id(), name, H5P_DEFAULT);
    db.write(analysis::reference_layout::durations, std::vector<double>{0.01, 0.02, 0.03});
    db.write(analysis::reference_layout::holdup, std::vector<double>{1.0, 2.0});
    db.setAttribute(analysis::reference_layout::holdup, "dt", kDt);
  };
  writeReference(job.scene.spray.spray_zone);
  const auto same = analysis::readReferenceStatistics(job.database, &job.scene.spray.spray_zone);
  EXPECT_TRUE(same.zoneMismatch.empty());
  EXPECT_EQ(same.durations.size(), 3u);
  SprayZoneSpec clipped = job.scene.spray.spray_zone;
  clipped.line_of_sight = true;
  for (const SprayZoneSpec& other : {clipped, [&] { auto z = job.scene.spray.spray_zone; z.y_max = 0.015; return z; }()}) {
    writeReference(other);
    const auto r = analysis::readReferenceStatistics(job.database, &job.scene.spray.spray_zone);
    EXPECT_FALSE(r.zoneMismatch.empty());
    EXPECT_TRUE(r.durations.empty());
    EXPECT_TRUE(r.holdup.empty());
    // Without a zone to hold it to, the reference is read as it is.
    EXPECT_EQ(analysis::readReferenceStatistics(job.database).durations.size(), 3u);
  }
  const json s = run(job, dir / "out");
  EXPECT_FALSE(s["reference"]["available"].get<bool>());
  EXPECT_NE(s["reference"]["zone_mismatch"].get<std::string>().find("y 0-0.015 m"), std::string::npos)
      << s["reference"]["zone_mismatch"];
  for (const auto& d : s["d0"]) EXPECT_TRUE(d["rtd_ks_distance"].is_null());
}

TEST(CalibrationJob, BadReferenceIsAnInputErrorNamingTheDataset) {
  const fs::path dir = scratch("badref");
  JobSpec job = makeJob(dir, {0.0, 1e-2});
  {
    h5::File db(job.database, h5::File::Mode::ReadWrite);
    db.write(analysis::reference_layout::holdup, std::vector<double>{1.0, 2.0});  // no dt attribute
  }
  try {
    run(job, dir / "out");
    FAIL() << "accepted a holdup series without dt";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/reference/holdup/particles@dt"), std::string::npos) << e.what();
  }
}

TEST(CalibrationJob, SameSeedSameResult) {
  const fs::path dir = scratch("determinism");
  JobSpec job = makeJob(dir);
  const json first = run(job, dir / "first");
  const json again = run(job, dir / "again");
  EXPECT_EQ(withoutWallTime(first), withoutWallTime(again));
  expectSameResults(dir / "first", dir / "again", 3);
  job.seed = 6;
  EXPECT_NE(run(job, dir / "other-seed")["d0"], first["d0"]) << "the seed must matter";
}

TEST(CalibrationJob, ThreadCountAndParallelModeDoNotMatter) {
  // More tracers than kParallelThreshold, so the tracer loops really run on 2 threads in "tracers"
  // mode; a shorter run keeps the test fast on a loaded machine.
  const fs::path dir = scratch("threads");
  JobSpec job = makeJob(dir, {0.0, 1e-2});
  job.scene.rcfd.tracers = 5000;
  job.duration = 60 * kDt;
  job.discard = 20 * kDt;
  setThreads(1);
  const json one = run(job, dir / "one");
  setThreads(2);
  const json two = run(job, dir / "two");
  job.source = {{"calibration", {{"parallel", "tracers"}}}};
  const json tracers = run(job, dir / "tracers");
  EXPECT_EQ(withoutWallTime(one), withoutWallTime(two));
  EXPECT_EQ(withoutWallTime(two), withoutWallTime(tracers));
  expectSameResults(dir / "one", dir / "two", 2);
  expectSameResults(dir / "two", dir / "tracers", 2);
}

TEST(CalibrationJob, ResumeAfterInterruptionEqualsAnUninterruptedRun) {
  const fs::path dir = scratch("resume");
  JobSpec job = makeJob(dir);
  const json reference = run(job, dir / "whole");

  // One D0 at a time: the first run finishes, the second stops 37 steps in.
  job.source = {{"calibration", {{"parallel", "tracers"}}}};
  EXPECT_THROW(run(job, dir / "split", kSteps + 37), Cancelled);
  EXPECT_TRUE(fs::exists(dir / "split/runs/d0_0/summary.json"));
  EXPECT_TRUE(fs::exists(dir / "split/runs/d0_1/checkpoint.h5"));
  EXPECT_FALSE(fs::exists(dir / "split/runs/d0_2"));
  EXPECT_FALSE(fs::exists(dir / "split/summary.json"));
  const auto finishedAt = fs::last_write_time(dir / "split/runs/d0_0/result.h5");
  const json resumed = run(job, dir / "split");
  EXPECT_EQ(fs::last_write_time(dir / "split/runs/d0_0/result.h5"), finishedAt) << "a finished D0 was run again";
  EXPECT_FALSE(fs::exists(dir / "split/runs/d0_1/checkpoint.h5"));
  EXPECT_EQ(withoutWallTime(resumed), withoutWallTime(reference));
  expectSameResults(dir / "whole", dir / "split", 3);

  // Several D0 at once, interrupted twice.
  job.source = json::object();
  EXPECT_THROW(run(job, dir / "parallel", 40), Cancelled);
  EXPECT_THROW(run(job, dir / "parallel", 200), Cancelled);
  EXPECT_EQ(withoutWallTime(run(job, dir / "parallel")), withoutWallTime(reference));
  expectSameResults(dir / "whole", dir / "parallel", 3);
}

/// The job run in this process with JSON progress on every report; returns the progress lines.
std::vector<json> runWithProgress(const JobSpec& job, const fs::path& out, long stopAfter = -1) {
  RunOptions o;
  o.outDir = out.string();
  o.stopAfterSteps = stopAfter;
  o.progressJson = true;
  o.progressInterval = 0.0;
  testing::internal::CaptureStdout();
  try {
    runJob(job, o);
  } catch (const Cancelled&) {
  }
  std::istringstream text(testing::internal::GetCapturedStdout());
  std::vector<json> lines;
  // In this process the log goes to stdout too (rcfd-solve sends it to stderr): only "{" lines are progress.
  for (std::string line; std::getline(text, line);)
    if (line.starts_with("{")) lines.push_back(json::parse(line));
  return lines;
}

TEST(CalibrationJob, ProgressMovesInEveryPhaseAndAResumeStartsFromTheStepsDone) {
  const fs::path dir = scratch("progress");
  JobSpec job = makeJob(dir);
  // One D0 at a time (a known split below), and the sweep as given (a sweep that grows has more to
  // do, and its fraction drops when it does).
  job.source = {{"calibration", {{"parallel", "tracers"}, {"extend_sweep", false}}}};
  const auto lines = runWithProgress(job, dir / "whole");
  ASSERT_FALSE(lines.empty());
  std::vector<std::string> phases;
  std::map<std::string, std::vector<double>> own;
  double last = -1.0;
  for (const auto& p : lines) {
    EXPECT_GE(p.at("fraction").get<double>(), last) << p.dump();
    last = p.at("fraction").get<double>();
    const std::string phase = p.value("phase", "");
    if (phases.empty() || phases.back() != phase) phases.push_back(phase);
    if (p.contains("phase_fraction")) own[phase].push_back(p.at("phase_fraction").get<double>());
  }
  EXPECT_EQ(last, 1.0);
  EXPECT_EQ(phases, (std::vector<std::string>{"recurrence", "runs", "report"}));
  for (const char* phase : {"recurrence", "runs"}) {
    const auto& f = own[phase];
    ASSERT_FALSE(f.empty()) << phase;
    EXPECT_TRUE(std::is_sorted(f.begin(), f.end())) << phase;
    EXPECT_EQ(f.front(), 0.0) << phase;
    EXPECT_EQ(f.back(), 1.0) << phase;
    EXPECT_GT(std::set<double>(f.begin(), f.end()).size(), 10u) << phase;
  }
  // The runs, summed over D0: a third of the phase per D0 value.
  EXPECT_NEAR(own["runs"][own["runs"].size() / 3], 1.0 / 3.0, 0.02);

  // Interrupted in the second D0's run: the resumed process counts the finished run and the
  // checkpoint's steps before anything runs, so its first line already says so.
  runWithProgress(job, dir / "split", kSteps + 37);
  const auto resumed = runWithProgress(job, dir / "split");
  ASSERT_FALSE(resumed.empty());
  const double stepsShare = double(kSteps + 37) / double(3 * kSteps);
  EXPECT_EQ(resumed.front().at("phase"), "recurrence");
  EXPECT_GT(resumed.front().at("fraction").get<double>(), 0.9 * stepsShare) << resumed.front().dump();
  EXPECT_LT(resumed.front().at("fraction").get<double>(), stepsShare + 1e-9) << resumed.front().dump();
  for (const auto& p : resumed) {
    if (p.value("phase", "") != "runs") continue;
    EXPECT_NEAR(p.at("phase_fraction").get<double>(), stepsShare, 1e-9) << "the first runs line: " << p.dump();
    break;
  }
}

TEST(CalibrationJob, BadInputNamesTheField) {
  const fs::path dir = scratch("bad");
  JobSpec job = makeJob(dir, {0.0, 1e-3, 1e-3});
  auto pointerOf = [&](const JobSpec& j) -> std::string {
    try {
      run(j, dir / "out");
    } catch (const InputError& e) {
      return e.violations().at(0).pointer;
    }
    return "(accepted)";
  };
  EXPECT_EQ(pointerOf(job), "/d0_values/2");
  job.d0_values = {0.0, 1e-3};
  job.discard = job.duration;
  EXPECT_EQ(pointerOf(job), "/discard");
  job.discard = 0.5;
  job.scene.probes.clear();
  EXPECT_EQ(pointerOf(job), "/scene/probes");
}

// Not part of the suite: times the two ways of sharing the threads (run with
// --gtest_also_run_disabled_tests --gtest_filter='*Timing*'; numbers in docs/calibration.md).
TEST(CalibrationJob, DISABLED_TimingOfParallelModes) {
  const fs::path dir = scratch("timing");
  JobSpec job = makeJob(dir, {0.0, 1e-5, 1e-4, 5e-4, 1e-3, 1e-2});
  job.scene.rcfd.tracers = 20000;  // the quick scene's tracer count
  for (const char* mode : {"d0_values", "tracers", "d0_values", "tracers"}) {
    job.source = {{"calibration", {{"parallel", mode}}}};
    const auto start = std::chrono::steady_clock::now();
    run(job, dir / mode);
    fs::remove_all(dir / mode);
    std::printf("parallel = %-9s: %.3f s wall\n", mode,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
}
