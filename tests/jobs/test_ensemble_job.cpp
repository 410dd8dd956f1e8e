// Spray jobs with an ensemble through the real rcfd-solve binary on a small analytic database (real
// HDF5 files): one member is the job without `ensemble` bit for bit, member k is the job of its seed,
// the statistics' band narrows as 1/sqrt(K), the thread count changes nothing, a resumed ensemble
// equals an uninterrupted one, and the schema bounds K.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "SolveProcess.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "jobs/Ensemble.hpp"
#include "scene/SceneLoader.hpp"

using nlohmann::json;
namespace fs = std::filesystem;

using rcfd::test::solve;
using rcfd::test::SolveResult;

namespace {

constexpr double kDuration = 2.0;  // [s]: 400 steps

/// A quick-like box: a spout swaying above a nozzle, a bed circulating beside it, droplets large enough
/// (f = 0.01) and a spray strong enough that 2 s spread the coverage over the histogram; more tracers
/// than the parallel threshold, so a member on two threads really splits its loops.
json sceneDocument() {
  return json::parse(R"({
    "name": "ensemble-job-test",
    "apparatus": {"type": "box", "size": [0.1, 0.15, 0.04], "outlet_top": true},
    "grid": {"cell_size": 0.01},
    "gas": {}, "particles": {},
    "process": {"bed_mass": 0.003},
    "rcfd": {"dt": 0.005, "tracers": 6000, "d0": 5e-4, "path": {"type": "paper"}},
    "spray": {"nozzle_position": [0.0, 0.005, 0.02], "nozzle_diameter": 0.002, "parcels_per_s": 4000,
              "droplet_diameter": 3.6e-4, "mass_rate": 2e-3,
              "spray_zone": {"apex": [0.0, 0.005, 0.02], "y_min": 0.01, "y_max": 0.08}},
    "probes": [{"name": "centre", "position": [0.0, 0.05, 0.02]}],
    "outputs": {"coverage_bins": 10},
    "effects": ["transport", "walls", "fluctuation", "free_flight", "tracer_volume_fraction", "probes",
                "residence_time", "spray", "deposition", "coverage", "deposition_maps"]
  })");
}

/// The run's datasets by path (strings as their text), for bit-for-bit comparisons.
void collect(const rcfd::h5::File& f, const std::string& group, std::map<std::string, std::string>& out) {
  for (const auto& name : f.children(group)) {
    const std::string path = (group == "/" ? "" : group) + "/" + name;
    try {
      if (name == "scene" || name == "summary") {
        out[path] = f.readString(path);
        continue;
      }
      const auto values = f.readDoubles(path);
      out[path] = std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
    } catch (const rcfd::RunError&) {  // a group
      collect(f, path, out);
    }
  }
}

std::map<std::string, std::string> datasets(const fs::path& file, const std::string& group = "/") {
  rcfd::h5::File f(file.string(), rcfd::h5::File::Mode::ReadOnly);
  std::map<std::string, std::string> out;
  collect(f, group, out);
  return out;
}

json summaryOf(const fs::path& out) {
  json s = json::parse(std::ifstream(out / "summary.json"));
  s.erase("wall_time_s");
  s.erase("tracer_steps_per_s");
  return s;
}

std::vector<std::string> filesIn(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// The pooled variance over bins of a histogram's member spread (sd) or band (sem).
double pooledSquares(const json& values) {
  double sum = 0.0;
  for (const auto& v : values) sum += v.get<double>() * v.get<double>();
  return sum;
}

class EnsembleJob : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::path(testing::TempDir()) / ("ensemble-job-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const json scene = sceneDocument();
    const rcfd::Scene s = rcfd::loadScene(scene);
    rcfd::Apparatus box(s.apparatus);
    const auto grid = rcfd::makeGrid(box, s.grid);
    const auto open = rcfd::openFractions(box, grid);
    const std::vector<float> fluid(open.begin(), open.end());
    // A spouted bed in a box: particles rise in a swaying spout, spread outwards above the bed, sink
    // through it and slide back in towards the spout, so every tracer keeps coming back to the spray.
    rcfd::writeAnalyticDatabase((dir_ / "db.h5").string(), grid, fluid, 0.005, 40,
                                [grid](int, double t, rcfd::FieldFrame& f) {
                                  const double centre = 0.005 * std::sin(2 * 3.14159265358979 * t / 0.1);
                                  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
                                    const auto ijk = grid.cellIjk(c);
                                    const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
                                    const double dx = p.x() - centre, side = dx < 0.0 ? -1.0 : 1.0;
                                    const bool spout = std::abs(dx) < 0.015, bed = p.y() < 0.09;
                                    const auto i = std::size_t(c);
                                    f.alpha_p[i] = float(spout ? 0.1 : (bed ? 0.5 : 0.01));
                                    f.u_p[3 * i] = float(spout ? 0.0 : (bed ? -0.4 * side : 0.5 * side));
                                    f.u_p[3 * i + 1] = float(spout ? 1.0 : (bed ? -0.4 : -0.5));
                                    f.u_g[3 * i + 1] = float(spout ? 6.0 : 1.0);
                                  }
                                },
                                scene.dump());
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  /// The job file: kDuration of seed 17, with `ensemble` unless null.
  static fs::path jobFile(const std::string& name, const json& ensemble, std::uint64_t seed = 17) {
    json job = {{"kind", "spray"}, {"scene", sceneDocument()}, {"database", (dir_ / "db.h5").string()},
                {"duration", kDuration}, {"seed", seed}, {"checkpoint_interval", 0.5}};
    if (!ensemble.is_null()) job["ensemble"] = ensemble;
    const fs::path path = dir_ / (name + ".json");
    std::ofstream(path) << job.dump(2);
    return path;
  }
  /// Runs a job once per suite (by name) and returns its output directory.
  /// Single runs on one thread: a team of two spinning on a loaded machine costs the suite seconds.
  static fs::path run(const std::string& name, const json& ensemble, const std::string& flags = "--threads 1",
                      std::uint64_t seed = 17) {
    const fs::path out = dir_ / name;
    if (fs::exists(out / "summary.json")) return out;
    const SolveResult r = solve("run " + jobFile(name, ensemble, seed).string() + " --out " + out.string() + " " + flags,
                                true);
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return out;
  }
  static fs::path dir_;
};

fs::path EnsembleJob::dir_;

}  // namespace

TEST_F(EnsembleJob, OneMemberIsBitForBitTheJobWithoutEnsemble) {
  const fs::path plain = run("plain", nullptr);
  for (const json& one : {json(1), json({{"members", 1}})}) {
    const fs::path out = run(one.is_object() ? "one-object" : "one", one);
    EXPECT_EQ(summaryOf(out).dump(), summaryOf(plain).dump());
    EXPECT_FALSE(summaryOf(out).contains("ensemble"));
    EXPECT_EQ(filesIn(out), filesIn(plain));
    EXPECT_EQ(datasets(out / "result.h5"), datasets(plain / "result.h5"));
    std::ifstream a(out / "coverage.svg"), b(plain / "coverage.svg");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(a), {}), std::string(std::istreambuf_iterator<char>(b), {}));
  }
}

TEST_F(EnsembleJob, MembersAreTheJobsOfTheirSeedsAndTheSummaryGivesMeanAndSpread) {
  const fs::path plain = run("plain", nullptr);
  const fs::path four = run("four", 4, "--threads 2");
  const json s = summaryOf(four);
  ASSERT_TRUE(s.contains("ensemble")) << s.dump(1);
  const json e = s["ensemble"];
  // Outside the block: member 0, the job of its seed without ensemble.
  json outside = s;
  outside.erase("ensemble");
  EXPECT_EQ(outside.dump(), summaryOf(plain).dump());
  const auto seeds = e["seeds"].get<std::vector<std::uint64_t>>();
  ASSERT_EQ(seeds, rcfd::ensembleSeeds(17, 4));
  EXPECT_EQ(e["members"], 4);

  // Every statistic as mean and spread over the members.
  for (const char* p : {"/coverage/mean", "/coverage/median", "/coverage/p10", "/coverage/p90", "/overspray_fraction",
                        "/holdup/mean", "/residence_time/mean_s", "/droplets_per_tracer_mean"}) {
    ASSERT_TRUE(e.contains(json::json_pointer(p))) << p;
    const json& st = e[json::json_pointer(p)];
    const auto v = st["values"].get<std::vector<double>>();
    ASSERT_EQ(v.size(), 4u) << p;
    EXPECT_EQ(v[0], s[json::json_pointer(p)].get<double>()) << p;  // member 0's value is the top-level one
    const double mean = (v[0] + v[1] + v[2] + v[3]) / 4.0;
    EXPECT_NEAR(st["mean"].get<double>(), mean, 1e-12 * std::abs(mean) + 1e-300) << p;
    EXPECT_NEAR(st["sem"].get<double>(), st["sd"].get<double>() / 2.0, 1e-15) << p;
    EXPECT_NEAR(st["ci95"][1].get<double>() - st["mean"].get<double>(), 3.18244631 * st["sem"].get<double>(),
                1e-6 * st["sem"].get<double>() + 1e-300) << p;
  }
  // The members differ: their own paths and placements.
  EXPECT_GT(e["coverage"]["mean"]["sd"].get<double>(), 0.0);
  const json& h = e["coverage"]["histogram"];
  EXPECT_EQ(h["edges"], s["coverage"]["histogram"]["edges"]);
  EXPECT_EQ(h["member_counts"][0], s["coverage"]["histogram"]["counts"]);
  double tracers = 0.0;
  for (const auto& c : h["mean"]) tracers += c.get<double>();
  EXPECT_NEAR(tracers, 6000.0, 1e-9);

  // Member 1 is the job run with its seed.
  const fs::path second = run("seed-of-member-1", nullptr, "--threads 1", seeds[1]);
  const json member1 = json::parse(rcfd::h5::File((four / "result.h5").string(), rcfd::h5::File::Mode::ReadOnly)
                                       .readString("/ensemble/members/01/summary"));
  json alone = summaryOf(second);
  alone.erase("figures");     // members other than 0 draw none
  alone.erase("kernel_isa");  // the job's, which the ensemble job's own summary carries
  EXPECT_EQ(member1.dump(), alone.dump());
  const auto root = datasets(four / "result.h5");
  const auto single = datasets(second / "result.h5");
  const auto m1 = datasets(four / "result.h5", "/ensemble/members/01");
  for (const auto& [path, bytes] : single) {
    if (path == "/scene") continue;
    ASSERT_TRUE(m1.count("/ensemble/members/01" + path)) << path;
    EXPECT_EQ(m1.at("/ensemble/members/01" + path), bytes) << path;
  }
  // The root is member 0's (the plain job's), and member 0's group links to it.
  for (const auto& [path, bytes] : datasets(plain / "result.h5")) {
    ASSERT_TRUE(root.count(path)) << path;
    EXPECT_EQ(root.at(path), bytes) << path;
    if (path != "/scene") {
      EXPECT_EQ(root.at("/ensemble/members/00" + path), bytes) << path;
    }
  }
  EXPECT_NE(root.at("/ensemble/members/01/path/frames"), root.at("/path/frames"));
  rcfd::h5::File r((four / "result.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  EXPECT_EQ(r.shape("/ensemble/coverage/histogram_counts"), (std::vector<hsize_t>{4, 10}));
  EXPECT_EQ(r.readDoubles("/ensemble/values/coverage/median"),
            e["coverage"]["median"]["values"].get<std::vector<double>>());
  EXPECT_EQ(r.readDoubles("/ensemble/coverage/histogram_sem"), h["sem"].get<std::vector<double>>());
  // The figure draws the band; the members' working files are gone.
  std::ifstream svg(four / "coverage.svg");
  const std::string text(std::istreambuf_iterator<char>(svg), {});
  EXPECT_NE(text.find("4 members"), std::string::npos);
  EXPECT_NE(text.find("#f0a030"), std::string::npos);
  EXPECT_FALSE(fs::exists(four / "members"));
  EXPECT_FALSE(fs::exists(four / "checkpoint.h5"));
}

TEST_F(EnsembleJob, ThreadCountDoesNotChangeTheResults) {
  const fs::path two = run("four", 4, "--threads 2");
  const fs::path one = run("four-one-thread", 4, "--threads 1");
  EXPECT_EQ(summaryOf(one).dump(), summaryOf(two).dump());
  EXPECT_EQ(datasets(one / "result.h5"), datasets(two / "result.h5"));
}

TEST_F(EnsembleJob, InterruptedAndResumedEqualsUninterrupted) {
  const fs::path whole = run("four", 4, "--threads 2");
  const fs::path out = dir_ / "four-resumed";
  const std::string job = jobFile("four-resumed", 4).string();
  // Stopped twice: while the first members run, and later (members finished, others checkpointed).
  for (const int steps : {250, 700}) {  // of 4 x 400
    const SolveResult r = solve("run " + job + " --out " + out.string() + " --threads 2 --stop-after-steps " +
                                std::to_string(steps), true);
    ASSERT_EQ(r.exitCode, 130) << r.out;
    EXPECT_TRUE(fs::exists(out / "members")) << r.out;
    EXPECT_FALSE(fs::exists(out / "summary.json"));
  }
  const SolveResult r = solve("run " + job + " --out " + out.string() + " --threads 1", true);
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_EQ(summaryOf(out).dump(), summaryOf(whole).dump());
  EXPECT_EQ(datasets(out / "result.h5"), datasets(whole / "result.h5"));
  EXPECT_EQ(filesIn(out), filesIn(whole));
}

// The histogram's band (the standard error of the members' mean count per bin) narrows as 1/sqrt(K):
// K = 16 against K = 4 (whose members are the first four of the 16). The members' own spread, what
// the band is made of, stays the same: it is the run-to-run scatter of one realisation.
TEST_F(EnsembleJob, BandNarrowsAsOneOverSqrtK) {
  const json four = summaryOf(run("four", 4, "--threads 2"))["ensemble"]["coverage"]["histogram"];
  const json sixteen = summaryOf(run("sixteen", 16, "--threads 2"))["ensemble"]["coverage"]["histogram"];
  const double sem4 = std::sqrt(pooledSquares(four["sem"])), sem16 = std::sqrt(pooledSquares(sixteen["sem"]));
  const double sd4 = std::sqrt(pooledSquares(four["sd"])), sd16 = std::sqrt(pooledSquares(sixteen["sd"]));
  ASSERT_GT(sem4, 0.0);
  // The pooled variance has about 3 x (bins with tracers) degrees of freedom for K = 4 and 15 x for
  // K = 16, so the ratio of the spreads is known within some 25 %; 1/sqrt(K) gives 0.5 for the band.
  EXPECT_NEAR(sd16 / sd4, 1.0, 0.4) << "sd4 " << sd4 << " sd16 " << sd16;
  EXPECT_NEAR(sem16 / sem4, 0.5, 0.2) << "sem4 " << sem4 << " sem16 " << sem16;
  // Per bin the band is sd / sqrt(K), and the larger ensemble's mean lies within the smaller's
  // interval in most bins (95 % each; the two share four members).
  int inside = 0, bins = 0;
  for (std::size_t b = 0; b < sixteen["mean"].size(); ++b) {
    EXPECT_NEAR(sixteen["sem"][b].get<double>(), sixteen["sd"][b].get<double>() / 4.0, 1e-12);
    if (four["sd"][b].get<double>() == 0.0) continue;
    ++bins;
    const double m = sixteen["mean"][b].get<double>();
    inside += m >= four["ci95_low"][b].get<double>() && m <= four["ci95_high"][b].get<double>();
  }
  ASSERT_GT(bins, 3);
  EXPECT_GE(inside, bins - 2) << inside << " of " << bins;
}

TEST_F(EnsembleJob, SchemaRefusesZeroAndSixtyFiveMembersNamingTheRange) {
  for (const json& k : {json(0), json(65), json({{"members", 0}}), json({{"members", 65}})}) {
    json job = json::parse(std::ifstream(jobFile("bounds", k)));
    try {
      rcfd::loadJob(job);
      ADD_FAILURE() << "accepted " << k.dump();
    } catch (const rcfd::InputError& e) {
      const std::string text = e.what();
      EXPECT_NE(text.find("/ensemble"), std::string::npos) << text;
      EXPECT_NE(text.find("[1, 64]"), std::string::npos) << text;
    }
    const SolveResult r = solve("validate " + jobFile("bounds", k).string(), true);
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("/ensemble"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("[1, 64]"), std::string::npos) << r.out;
  }
  for (const json& k : {json(1), json(64), json({{"members", 2}})}) {
    EXPECT_NO_THROW(rcfd::loadJob(json::parse(std::ifstream(jobFile("bounds", k))))) << k.dump();
  }
  json calibration = json::parse(std::ifstream(jobFile("calibration", 4)));
  calibration["kind"] = "calibration";
  try {
    rcfd::loadJob(calibration);
    ADD_FAILURE() << "a calibration job took an ensemble";
  } catch (const rcfd::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("only spray jobs take \"ensemble\""), std::string::npos) << e.what();
  }
}
