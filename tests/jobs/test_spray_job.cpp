// The spray job through the real rcfd-solve binary: a database file, a job file, progress lines,
// SIGTERM-style interruption (exit 130 with a checkpoint) and resume equal to an uninterrupted run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sys/wait.h>

#include "SolveProcess.hpp"
#include "core/Hdf5.hpp"
#include "core/Isa.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "scene/SceneLoader.hpp"

using nlohmann::json;
namespace fs = std::filesystem;

using rcfd::test::kSolver;
using rcfd::test::solve;
using rcfd::test::SolveResult;

namespace {


json sceneDocument() {
  return json::parse(R"({
    "name": "spray-job-test",
    "apparatus": {"type": "box", "size": [0.1, 0.15, 0.04], "outlet_top": true},
    "grid": {"cell_size": 0.01},
    "gas": {}, "particles": {},
    "process": {"bed_mass": 0.3},
    "rcfd": {"dt": 0.005, "tracers": 5000, "d0": 5e-4, "path": {"type": "paper"}},
    "spray": {"nozzle_position": [0.0, 0.005, 0.02], "nozzle_diameter": 0.002, "parcels_per_s": 4000,
              "spray_zone": {"apex": [0.0, 0.005, 0.02], "y_min": 0.01, "y_max": 0.08}},
    "probes": [{"name": "centre", "position": [0.0, 0.05, 0.02]}],
    "effects": ["transport", "walls", "fluctuation", "free_flight", "tracer_volume_fraction", "probes",
                "residence_time", "spray", "deposition", "coverage", "deposition_maps"]
  })");
}

class SprayJob : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("spray-job-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const json scene = sceneDocument();
    const rcfd::Scene s = rcfd::loadScene(scene);
    rcfd::Apparatus box(s.apparatus);
    const auto grid = rcfd::makeGrid(box, s.grid);
    const auto open = rcfd::openFractions(box, grid);
    const std::vector<float> fluid(open.begin(), open.end());
    rcfd::writeAnalyticDatabase((dir_ / "db.h5").string(), grid, fluid, 0.005, 40,
                                [grid](int n, double t, rcfd::FieldFrame& f) {
                                  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
                                    const auto ijk = grid.cellIjk(c);
                                    const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
                                    const double phase = 2 * 3.14159265358979 * t / 0.1;  // period 20 frames
                                    const bool spout = std::abs(p.x() - 0.01 * std::sin(phase)) < 0.02;
                                    f.alpha_p[std::size_t(c)] = float(p.y() < 0.07 ? (spout ? 0.15 : 0.5) : 0.0);
                                    f.u_p[3 * c + 1] = float(spout ? 1.0 : -0.2);
                                    f.u_g[3 * c + 1] = float(spout ? 6.0 : 1.0);
                                    f.u_g[3 * c] = float(0.5 * std::sin(phase + 40 * p.y()) + 0.01 * n);
                                  }
                                },
                                scene.dump());
    const json job = {{"kind", "spray"}, {"scene", scene}, {"database", (dir_ / "db.h5").string()},
                      {"duration", 0.4}, {"seed", 17}, {"checkpoint_interval", 0.1}};
    std::ofstream(dir_ / "job.json") << job.dump(2);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static json summaryOf(const fs::path& out) {
    json s = json::parse(std::ifstream(out / "summary.json"));
    s.erase("wall_time_s");
    s.erase("tracer_steps_per_s");
    return s;
  }
  fs::path dir_;
};

}  // namespace

TEST_F(SprayJob, RunsAndReportsProgressAndTheContractKeys) {
  const SolveResult r = solve("run " + (dir_ / "job.json").string() + " --out " + (dir_ / "a").string() +
                              " --progress-json --progress-interval 0");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  // Progress lines: one JSON object each, fraction rising to 1; the phases in order, the recurrence
  // set-up (reading the frames, the matrix) and the run each moving on their own.
  std::istringstream lines(r.out);
  std::string line;
  double last = -1.0;
  int count = 0;
  std::vector<std::string> phases;
  std::map<std::string, std::vector<double>> own;
  while (std::getline(lines, line)) {
    const json p = json::parse(line);
    ASSERT_TRUE(p.contains("fraction") && p.contains("sim_time") && p.contains("wall_time") && p.contains("eta_s"));
    EXPECT_GE(p["fraction"].get<double>(), last);
    last = p["fraction"].get<double>();
    ++count;
    const std::string phase = p.value("phase", "");
    if (phases.empty() || phases.back() != phase) phases.push_back(phase);
    if (p.contains("phase_fraction")) own[phase].push_back(p["phase_fraction"].get<double>());
  }
  EXPECT_GE(count, 1);
  EXPECT_EQ(last, 1.0);
  EXPECT_EQ(phases, (std::vector<std::string>{"recurrence", "run", "results"}));
  for (const char* phase : {"recurrence", "run"}) {
    const auto& f = own[phase];
    EXPECT_TRUE(std::is_sorted(f.begin(), f.end())) << phase;
    EXPECT_GT(std::set<double>(f.begin(), f.end()).size(), 10u) << phase;
    ASSERT_FALSE(f.empty());
    EXPECT_EQ(f.front(), 0.0) << phase;
    EXPECT_EQ(f.back(), 1.0) << phase;
  }
  const json s = json::parse(std::ifstream(dir_ / "a" / "summary.json"));
  for (const char* key : {"kind", "status", "seed", "wall_time_s", "steps", "sim_time_s", "effects", "tracers",
                          "tracer_steps_per_s", "mass_balance", "overspray_fraction", "coverage",
                          "droplets_per_tracer_mean", "residence_time", "holdup"}) {
    EXPECT_TRUE(s.contains(key)) << key;
  }
  EXPECT_EQ(s["steps"].get<int>(), 80);
  EXPECT_EQ(s["status"], "succeeded");
  EXPECT_EQ(s["kernel_isa"], rcfd::isaName(rcfd::kernelIsa()));  // the solver runs on this CPU with this environment
  const auto& m = s["mass_balance"];
  EXPECT_LE(std::abs(m["closure_error_kg"].get<double>()), 1e-9 * m["injected_kg"].get<double>());
  EXPECT_TRUE(fs::exists(dir_ / "a" / "result.h5"));
  EXPECT_TRUE(fs::exists(dir_ / "a" / "coverage.svg"));
  EXPECT_TRUE(fs::exists(dir_ / "a" / "deposition_z.svg"));
  EXPECT_FALSE(fs::exists(dir_ / "a" / "checkpoint.h5"));
}

TEST_F(SprayJob, ComparesItsStaysWithTheDatabasesReferenceWhenThereIsOne) {
  ASSERT_EQ(solve("run " + (dir_ / "job.json").string() + " --out " + (dir_ / "plain").string()).exitCode, 0);
  EXPECT_TRUE(json::parse(std::ifstream(dir_ / "plain" / "summary.json"))["stay_comparison"].is_null());
  {  // 300 reference stays of 0.02 s (4 steps exactly), of 100 parcels over 1 s
    rcfd::h5::File db((dir_ / "db.h5").string(), rcfd::h5::File::Mode::ReadWrite);
    db.write("/reference/residence_time/durations_s", std::vector<double>(300, 0.02));
    db.setAttribute("/reference/residence_time/durations_s", "dt", 0.001);
    db.setAttribute("/reference/residence_time/durations_s", "members", 100.0);
    db.setAttribute("/reference/residence_time/durations_s", "period_s", 1.0);
  }
  ASSERT_EQ(solve("run " + (dir_ / "job.json").string() + " --out " + (dir_ / "ref").string()).exitCode, 0);
  const json s = json::parse(std::ifstream(dir_ / "ref" / "summary.json"));
  const json& c = s["stay_comparison"];
  ASSERT_TRUE(c.is_object()) << s.dump(1);
  EXPECT_DOUBLE_EQ(c["lattice_dt_s"].get<double>(), 0.005);
  EXPECT_NEAR(c["reference"]["mean_s"].get<double>(), 0.02, 1e-12);
  // 3 stays per parcel per second seen through a 1 s window: each weighted by 1 s / (1 s - 0.02 s).
  EXPECT_NEAR(c["reference"]["crossings_per_member_per_s"].get<double>(), 3.0 / 0.98, 1e-9);
  EXPECT_EQ(c["reference_unseen_fraction"].get<double>(), 0.0);
  const json& window = c["window"];
  EXPECT_EQ(window["reference_s"].get<double>(), 1.0);
  EXPECT_NEAR(window["longest_compared_s"].get<double>(), 0.5 * std::min(1.0, window["tracers_s"].get<double>()), 1e-12);
  // The tracers' own stays up to the longest compared, each weighted by between 1 and 2 for their window.
  const double rawStays = s["residence_time"]["stays"].get<double>();
  const double compared = rawStays * (1.0 - window["tracers_beyond_fraction"].get<double>());
  EXPECT_LT(window["tracers_beyond_fraction"].get<double>(), 0.05);
  EXPECT_GE(c["tracers"]["stays"].get<double>(), compared - 1e-9);
  EXPECT_LE(c["tracers"]["stays"].get<double>(), 2.0 * compared);
  EXPECT_NEAR(c["tracers"]["crossings_per_member_per_s"].get<double>() / c["tracers"]["stays"].get<double>(),
              s["residence_time"]["crossings_per_tracer_per_s"].get<double>() / rawStays, 1e-12);
  EXPECT_GE(c["ks_distance"].get<double>(), 0.0);
  EXPECT_LE(c["ks_distance"].get<double>(), 1.0);
}

TEST_F(SprayJob, ComparesItsCoverageWithTheDatabasesReferenceCoverage) {
  ASSERT_EQ(solve("run " + (dir_ / "job.json").string() + " --out " + (dir_ / "plain").string()).exitCode, 0);
  EXPECT_TRUE(json::parse(std::ifstream(dir_ / "plain" / "summary.json"))["coverage_comparison"].is_null());
  // The run's own droplets per particle as the reference over its duration: distance 0, errors 0. Then
  // every reference particle far more coated.
  const json plain = json::parse(std::ifstream(dir_ / "plain" / "summary.json"));
  std::vector<double> droplets;
  {
    rcfd::h5::File result((dir_ / "plain" / "result.h5").string(), rcfd::h5::File::Mode::ReadOnly);
    droplets = result.readDoubles("/coverage/droplets_per_particle");
  }
  const double singleDrop = plain["coverage"]["f"].get<double>();
  // A copy of the database with the given reference coverage, and a job on it.
  auto jobWithReference = [&](const std::string& name, const std::vector<double>& values, double duration) {
    const fs::path db = dir_ / (name + ".h5");
    fs::copy_file(dir_ / "db.h5", db, fs::copy_options::overwrite_existing);
    {
      rcfd::h5::File f(db.string(), rcfd::h5::File::Mode::ReadWrite);
      const char* set = "/reference/coverage/droplets_per_particle";
      f.write(set, values);
      f.setAttribute(set, "duration_s", duration);
      f.setAttribute(set, "dt", 0.001);
      f.setAttribute(set, "particles_per_parcel", plain["particles_per_tracer"].get<double>());
      f.setAttribute(set, "f", singleDrop);
    }
    json job = json::parse(std::ifstream(dir_ / "job.json"));
    job["database"] = db.string();
    const fs::path path = dir_ / (name + ".json");
    std::ofstream(path) << job.dump(2);
    return path.string();
  };
  auto comparisonOf = [&](const std::string& name, const std::vector<double>& values, double duration) {
    const std::string job = jobWithReference(name, values, duration);
    EXPECT_EQ(solve("run " + job + " --out " + (dir_ / name).string()).exitCode, 0);
    return json::parse(std::ifstream(dir_ / name / "summary.json"))["coverage_comparison"];
  };
  const json same = comparisonOf("same", droplets, 0.4);
  ASSERT_TRUE(same.is_object());
  EXPECT_TRUE(same["same_duration"].get<bool>());
  EXPECT_EQ(same["ks_distance"].get<double>(), 0.0);
  EXPECT_EQ(same["mean_relative_error"].get<double>(), 0.0);
  EXPECT_FALSE(same.contains("note")) << same.dump(1);
  // Every reference particle above the run's most coated one: the distributions do not overlap (KS 1).
  const double top = *std::max_element(droplets.begin(), droplets.end()) + 1.0;
  std::vector<double> above = droplets;
  double mean = 0.0;
  for (double& v : above) mean += v, v += top;
  mean /= double(droplets.size());
  const json less = comparisonOf("above", above, 0.4);
  EXPECT_EQ(less["ks_distance"].get<double>(), 1.0);
  EXPECT_NEAR(less["droplets_per_particle_relative_error"].get<double>(), mean / (mean + top) - 1.0, 1e-9);
  // Another duration: reported, not compared.
  const json other = comparisonOf("other", droplets, 2.0);
  EXPECT_FALSE(other["same_duration"].get<bool>());
  EXPECT_FALSE(other.contains("ks_distance"));
}

TEST_F(SprayJob, InterruptedAndResumedEqualsUninterrupted) {
  ASSERT_EQ(solve("run " + (dir_ / "job.json").string() + " --out " + (dir_ / "a").string()).exitCode, 0);
  const SolveResult stopped =
      solve("run " + (dir_ / "job.json").string() + " --out " + (dir_ / "b").string() + " --stop-after-steps 33");
  EXPECT_EQ(stopped.exitCode, 130);
  ASSERT_TRUE(fs::exists(dir_ / "b" / "checkpoint.h5"));
  EXPECT_FALSE(fs::exists(dir_ / "b" / "summary.json"));
  ASSERT_EQ(solve("run " + (dir_ / "job.json").string() + " --out " + (dir_ / "b").string()).exitCode, 0);
  EXPECT_EQ(summaryOf(dir_ / "a").dump(), summaryOf(dir_ / "b").dump());
  rcfd::h5::File a((dir_ / "a" / "result.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  rcfd::h5::File b((dir_ / "b" / "result.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  for (const char* set : {"/tracers/x", "/tracers/y", "/coverage/droplets_per_particle", "/holdup/particles",
                          "/deposition_maps/rate_density"}) {
    EXPECT_EQ(a.readDoubles(set), b.readDoubles(set)) << set;
  }
}

TEST_F(SprayJob, BadInputsExitTwoNamingTheField) {
  json job = json::parse(std::ifstream(dir_ / "job.json"));
  job["scene"]["rcfd"]["dt"] = 0.003;  // does not divide dt_rec = 0.005
  std::ofstream(dir_ / "bad.json") << job.dump();
  FILE* pipe = popen((kSolver + " run " + (dir_ / "bad.json").string() + " --out " + (dir_ / "c").string() +
                      " 2>&1").c_str(), "r");
  std::string text;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) text += buffer;
  const int status = pclose(pipe);
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_NE(text.find("/rcfd/dt"), std::string::npos) << text;
  job = json::parse(std::ifstream(dir_ / "job.json"));
  job["database"] = (dir_ / "missing.h5").string();
  std::ofstream(dir_ / "bad2.json") << job.dump();
  EXPECT_NE(solve("run " + (dir_ / "bad2.json").string() + " --out " + (dir_ / "d").string()).exitCode, 0);
}

TEST_F(SprayJob, CoverageFigureDrawsSeveralRunsWithTheirSummariesStatistics) {
  json job = json::parse(std::ifstream(dir_ / "job.json"));
  job["duration"] = 0.2;
  std::ofstream(dir_ / "short.json") << job.dump();
  ASSERT_EQ(solve("run " + (dir_ / "job.json").string() + " --out " + (dir_ / "a").string()).exitCode, 0);
  ASSERT_EQ(solve("run " + (dir_ / "short.json").string() + " --out " + (dir_ / "b").string()).exitCode, 0);
  const fs::path svg = dir_ / "figs" / "coverage.svg";
  const SolveResult r = solve("coverage-figure " + (dir_ / "a" / "result.h5").string() + " " +
                              (dir_ / "b" / "result.h5").string() + " --label long --label short --out " +
                              svg.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const json stats = json::parse(r.out);
  ASSERT_EQ(stats.size(), 2u);
  for (const auto& [k, dir] : {std::pair{0, "a"}, std::pair{1, "b"}}) {
    const json c = json::parse(std::ifstream(dir_ / dir / "summary.json"))["coverage"];
    // Quantiles exactly; the mean to round-off (result.h5 holds the tracers in id order, the summary
    // sums them in the run's order).
    for (const char* q : {"median", "p10", "p90"}) EXPECT_EQ(stats[k][q], c[q]) << dir << " " << q;
    EXPECT_NEAR(stats[k]["mean"].get<double>(), c["mean"].get<double>(), 1e-12 * c["mean"].get<double>()) << dir;
  }
  EXPECT_EQ(stats[0]["label"], "long");
  EXPECT_GT(stats[0]["mean"].get<double>(), stats[1]["mean"].get<double>());  // twice the spray time
  std::ifstream in(svg);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("long: mean"), std::string::npos);
  EXPECT_NE(text.find("short: mean"), std::string::npos);

  // A file without coverage, and labels that do not match the files: exit 2 naming what is wrong.
  const SolveResult noCoverage = solve("coverage-figure " + (dir_ / "db.h5").string() + " --out " +
                                       (dir_ / "x.svg").string(), /*withStderr=*/true);
  EXPECT_EQ(noCoverage.exitCode, 2);
  EXPECT_NE(noCoverage.out.find("/coverage/per_tracer"), std::string::npos) << noCoverage.out;
  const SolveResult labels = solve("coverage-figure " + (dir_ / "a" / "result.h5").string() + " " +
                                   (dir_ / "b" / "result.h5").string() + " --label one --out " +
                                   (dir_ / "y.svg").string(), /*withStderr=*/true);
  EXPECT_EQ(labels.exitCode, 2);
  EXPECT_NE(labels.out.find("--label"), std::string::npos) << labels.out;
  EXPECT_FALSE(fs::exists(dir_ / "x.svg"));
}
