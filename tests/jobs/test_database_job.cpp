// The database job through the real rcfd-solve binary on a DEM-only scene (no `gas`): a few hundred
// parcels settle in a small box and are sampled as they lie. database.h5 must load with the field
// database reader, hold duration * rate frames whose alpha_P integrates to the parcels' volume and
// whose u_P is zero where alpha_P is; a job stopped and resumed (also from an older checkpoint, with
// frames on disk that it must cut back) writes exactly what an uninterrupted one writes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>

#include "analysis/ReferenceStatistics.hpp"
#include "SmallScenes.hpp"
#include "SolveProcess.hpp"
#include "core/Hdf5.hpp"
#include "fields/FieldDatabase.hpp"

using nlohmann::json;
namespace fs = std::filesystem;

using rcfd::test::kSolver;
using rcfd::test::solve;
using rcfd::test::SolveResult;

namespace {

/// Component-wise lowest and highest u_P of the 26 neighbours of cell c that hold particle volume;
/// none when no neighbour does.
std::optional<std::pair<std::array<float, 3>, std::array<float, 3>>> neighbourVelocityRange(
    const rcfd::FieldFrame& f, const rcfd::CartesianGrid& grid, std::size_t c) {
  const auto ijk = grid.cellIjk(std::int64_t(c));
  std::optional<std::pair<std::array<float, 3>, std::array<float, 3>>> range;
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const int i = ijk[0] + di, j = ijk[1] + dj, k = ijk[2] + dk;
        if (i < 0 || j < 0 || k < 0 || i >= grid.shape[0] || j >= grid.shape[1] || k >= grid.shape[2]) continue;
        const auto n = std::size_t(grid.flatIndex(i, j, k));
        if (n == c || !(f.alpha_p[n] > 0.0f)) continue;
        if (!range) range.emplace(std::array<float, 3>{f.u_p[3 * n], f.u_p[3 * n + 1], f.u_p[3 * n + 2]},
                                  std::array<float, 3>{f.u_p[3 * n], f.u_p[3 * n + 1], f.u_p[3 * n + 2]});
        for (std::size_t d = 0; d < 3; ++d) {
          range->first[d] = std::min(range->first[d], f.u_p[3 * n + d]);
          range->second[d] = std::max(range->second[d], f.u_p[3 * n + d]);
        }
      }
  return range;
}

constexpr double kParcelDiameter = 0.003;
constexpr double kDensity = 1040.0;
constexpr double kBedMass = 0.005;  // 340 parcels of 3 mm

json sceneDocument() { return rcfd::test::demOnlyDatabaseScene(); }

class DatabaseJob : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("database-job-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    writeJob(sceneDocument(), "job.json");
  }
  void TearDown() override { fs::remove_all(dir_); }

  void writeJob(const json& scene, const std::string& name, double checkpointInterval = 1.0) {
    const json job = {{"kind", "database"}, {"scene", scene}, {"seed", 3}, {"checkpoint_interval", checkpointInterval}};
    std::ofstream(dir_ / name) << job.dump(2);
  }
  std::string run(const std::string& out, const std::string& extra = "", const std::string& job = "job.json") {
    return "run " + (dir_ / job).string() + " --out " + (dir_ / out).string() + " " + extra;
  }
  static json summaryOf(const fs::path& out) {
    json s = json::parse(std::ifstream(out / "summary.json"));
    s.erase("wall_time_s");
    s.erase("parcel_steps_per_s");
    return s;
  }
  fs::path dir_;
};

void expectSameDatabase(const fs::path& a, const fs::path& b) {
  auto da = rcfd::FieldDatabase::open(a.string());
  auto db = rcfd::FieldDatabase::open(b.string());
  ASSERT_EQ(da->frameCount(), db->frameCount());
  for (int n = 0; n < da->frameCount(); ++n) {
    EXPECT_EQ(da->frame(n)->alpha_p, db->frame(n)->alpha_p) << "frame " << n;
    EXPECT_EQ(da->frame(n)->u_p, db->frame(n)->u_p) << "frame " << n;
    EXPECT_EQ(da->frame(n)->u_g, db->frame(n)->u_g) << "frame " << n;
  }
  rcfd::h5::File fa(a.string(), rcfd::h5::File::Mode::ReadOnly), fb(b.string(), rcfd::h5::File::Mode::ReadOnly);
  for (const char* set : {"/reference/holdup/particles", "/reference/pressure_drop/pa", "/reference/probes/u_p_y"}) {
    EXPECT_EQ(fa.readDoubles(set), fb.readDoubles(set)) << set;
  }
}

/// With the gas a resumed run is not bit-identical: the coupling rebuilds the pressure preconditioner
/// after a load, so the pressure (and through it everything) differs at the solver tolerance
/// (tests/coupling/test_state.cpp). Values agree to `tolerance` (relative, floor 1 in the unit).
void expectCloseValues(const std::vector<float>& a, const std::vector<float>& b, double tolerance,
                       const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, std::abs(double(a[i]) - double(b[i])) / std::max(1.0, std::abs(double(a[i]))));
  EXPECT_LE(worst, tolerance) << what;
}

void expectCloseDatabase(const fs::path& a, const fs::path& b, double tolerance) {
  auto da = rcfd::FieldDatabase::open(a.string());
  auto db = rcfd::FieldDatabase::open(b.string());
  ASSERT_EQ(da->frameCount(), db->frameCount());
  for (int n = 0; n < da->frameCount(); ++n) {
    expectCloseValues(da->frame(n)->alpha_p, db->frame(n)->alpha_p, tolerance, "alpha_p " + std::to_string(n));
    expectCloseValues(da->frame(n)->u_p, db->frame(n)->u_p, tolerance, "u_p " + std::to_string(n));
    expectCloseValues(da->frame(n)->u_g, db->frame(n)->u_g, tolerance, "u_g " + std::to_string(n));
  }
  rcfd::h5::File fa(a.string(), rcfd::h5::File::Mode::ReadOnly), fb(b.string(), rcfd::h5::File::Mode::ReadOnly);
  for (const char* set : {"/reference/pressure_drop/pa", "/reference/probes/u_p_y"}) {
    const auto x = fa.readDoubles(set), y = fb.readDoubles(set);
    expectCloseValues(std::vector<float>(x.begin(), x.end()), std::vector<float>(y.begin(), y.end()), tolerance, set);
  }
  const auto ha = fa.readDoubles("/reference/holdup/particles"), hb = fb.readDoubles("/reference/holdup/particles");
  ASSERT_EQ(ha.size(), hb.size());
  for (std::size_t i = 0; i < ha.size(); ++i) EXPECT_NEAR(ha[i], hb[i], 1.0) << "holdup sample " << i;
}

}  // namespace

TEST_F(DatabaseJob, DemOnlyJobWritesALoadableDatabaseAndTheContractKeys) {
  const SolveResult r = solve(run("a", "--progress-json --progress-interval 0"));
  ASSERT_EQ(r.exitCode, 0) << r.out;
  // Progress: JSON lines, fraction non-decreasing up to 1, every phase named in order and moving:
  // the whole job's fraction and the phase's own, from the filling on.
  std::istringstream lines(r.out);
  std::string line;
  double last = -1.0;
  std::vector<std::string> phases;
  std::map<std::string, std::vector<double>> fractions, phaseFractions;
  while (std::getline(lines, line)) {
    const json p = json::parse(line);
    ASSERT_TRUE(p.contains("fraction") && p.contains("eta_s") && p.contains("sim_time"));
    EXPECT_GE(p["fraction"].get<double>(), last);
    last = p["fraction"].get<double>();
    const std::string phase = p.value("phase", "");
    if (phases.empty() || phases.back() != phase) phases.push_back(phase);
    fractions[phase].push_back(last);
    if (p.contains("phase_fraction")) phaseFractions[phase].push_back(p["phase_fraction"].get<double>());
  }
  EXPECT_EQ(last, 1.0);
  EXPECT_EQ(phases, (std::vector<std::string>{"fill", "settle", "warmup", "sample", "reference", "results"}));
  for (const char* phase : {"fill", "settle", "warmup", "sample", "reference"}) {
    const auto& f = fractions[phase];
    const auto& own = phaseFractions[phase];
    ASSERT_GT(f.size(), 10u) << phase;
    EXPECT_GT(std::set<double>(f.begin(), f.end()).size(), 10u) << phase << ": the whole job's fraction moves";
    ASSERT_GT(own.size(), 10u) << phase;
    EXPECT_TRUE(std::is_sorted(own.begin(), own.end())) << phase;
    EXPECT_GT(std::set<double>(own.begin(), own.end()).size(), 10u) << phase << ": the phase's fraction moves";
    EXPECT_LE(own.front(), 0.2) << phase;
    EXPECT_GE(own.back(), 0.8) << phase;
  }
  EXPECT_GT(fractions["fill"].back(), 0.0);
  EXPECT_GT(fractions["settle"].back(), fractions["fill"].back());

  const json s = json::parse(std::ifstream(dir_ / "a" / "summary.json"));
  for (const char* key : {"kind", "status", "seed", "wall_time_s", "steps", "sim_time_s", "effects", "frames",
                          "dt_rec", "particles", "parcel_steps_per_s", "pressure_drop", "residence_time", "holdup",
                          "sampling_criterion", "probes", "figures"}) {
    EXPECT_TRUE(s.contains(key)) << key;
  }
  EXPECT_EQ(s["kind"], "database");
  EXPECT_EQ(s["status"], "succeeded");
  EXPECT_EQ(s["effects"], json::array({"rolling_friction"}));
  EXPECT_FALSE(s["gas"].get<bool>());
  EXPECT_EQ(s["frames"].get<int>(), 10);  // 0.05 s at 200 Hz
  EXPECT_DOUBLE_EQ(s["dt_rec"].get<double>(), 0.005);
  for (const char* key : {"mean_pa", "std_pa", "dominant_frequency_hz"}) EXPECT_TRUE(s["pressure_drop"].contains(key));
  EXPECT_DOUBLE_EQ(s["pressure_drop"]["mean_pa"].get<double>(), 0.0);  // no gas
  EXPECT_TRUE(s["pressure_drop"]["dominant_frequency_hz"].is_null());
  EXPECT_TRUE(s["reference_coverage"].is_null());  // the scene asks for no coverage
  for (const char* key : {"mean_s", "median_s", "histogram"}) EXPECT_TRUE(s["residence_time"].contains(key));
  EXPECT_TRUE(s["holdup"].contains("mean"));
  // Blow-out: a settled DEM-only bed of 340 parcels in a 0.1 m box stays at the bottom: its highest
  // parcel top lies a few centimetres up, and reaching the top between two 1 ms samples would take
  // tens of m/s.
  const json& blow = s["blow_out"];
  EXPECT_DOUBLE_EQ(blow["chamber_top_m"].get<double>(), 0.1);
  EXPECT_GT(blow["highest_parcel_top_m"].get<double>(), kParcelDiameter);
  EXPECT_LT(blow["highest_parcel_top_m"].get<double>(), 0.05);
  EXPECT_DOUBLE_EQ(blow["sample_interval_s"].get<double>(), 1e-3);
  EXPECT_GT(blow["speed_to_reach_top_m_per_s"].get<double>(), 10.0);
  EXPECT_EQ(blow["parcels_reaching_top"].get<int>(), 0);
  EXPECT_EQ(blow["fraction_reaching_top"].get<double>(), 0.0);
  EXPECT_FALSE(fs::exists(dir_ / "a" / "checkpoint.h5"));
  EXPECT_TRUE(fs::exists(dir_ / "a" / "result.h5"));
  EXPECT_TRUE(fs::exists(dir_ / "a" / "database_alpha_p.svg"));

  const long parcels = s["particles"].get<long>();
  const long expectedParcels = std::lround(kBedMass / (kDensity * std::numbers::pi / 6 * std::pow(kParcelDiameter, 3)));
  EXPECT_EQ(parcels, expectedParcels);
  const double parcelVolume = std::numbers::pi / 6 * std::pow(kParcelDiameter, 3);

  auto db = rcfd::FieldDatabase::open((dir_ / "a" / "database.h5").string());
  ASSERT_EQ(db->frameCount(), 10);
  EXPECT_DOUBLE_EQ(db->dtRec(), 0.005);
  const double cellVolume = db->grid().cellVolume();
  for (int n = 0; n < db->frameCount(); ++n) {
    const auto f = db->frame(n);
    double volume = 0.0;
    long filled = 0;
    for (std::size_t c = 0; c < f->alpha_p.size(); ++c) {
      volume += double(f->alpha_p[c]) * cellVolume * db->fluidFraction()[c];
      if (f->alpha_p[c] == 0.0f) {
        // An empty cell has the velocity of the particle volume next to it (a weighted mean), or none.
        const auto range = neighbourVelocityRange(*f, db->grid(), c);
        for (int d = 0; d < 3; ++d) {
          const float u = f->u_p[3 * c + std::size_t(d)];
          if (!range) {
            EXPECT_EQ(u, 0.0f) << "empty cell " << c;
            continue;
          }
          EXPECT_GE(u, range->first[std::size_t(d)] - 1e-6f) << "empty cell " << c;
          EXPECT_LE(u, range->second[std::size_t(d)] + 1e-6f) << "empty cell " << c;
        }
      } else {
        ++filled;
      }
      for (int d = 0; d < 3; ++d) EXPECT_EQ(f->u_g[3 * c + std::size_t(d)], 0.0f);  // no gas
    }
    EXPECT_NEAR(volume, double(parcels) * parcelVolume, 1e-4 * double(parcels) * parcelVolume) << "frame " << n;
    EXPECT_GT(filled, 0);
    EXPECT_LT(filled, long(f->alpha_p.size()));  // the bed does not fill the box
  }
  // The reference series: reference_duration * probe_rate holdup samples, all samples of the
  // pressure drop and probes; the calibration's reader accepts the holdup.
  const auto ref = rcfd::analysis::readReferenceStatistics((dir_ / "a" / "database.h5").string());
  EXPECT_EQ(ref.holdup.size(), 30u);
  EXPECT_DOUBLE_EQ(ref.holdupDt, 0.001);
  rcfd::h5::File f((dir_ / "a" / "database.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  EXPECT_EQ(f.readDoubles("/reference/pressure_drop/pa").size(), 80u);
  EXPECT_EQ(f.shape("/reference/probes/u_p_y"), (std::vector<hsize_t>{80, 2}));
  // The probe above the bed sees no parcel: u_P,y = 0 throughout.
  const auto probes = f.readDoubles("/reference/probes/u_p_y");
  for (std::size_t i = 1; i < probes.size(); i += 2) EXPECT_EQ(probes[i], 0.0);
  EXPECT_GT(s["probes"][0]["alpha_p_mean"].get<double>(), 0.2);   // in the settled bed
  EXPECT_EQ(s["probes"][1]["alpha_p_mean"].get<double>(), 0.0);  // above it

  // rcfd-solve database-figures draws the same figures from the file and reports the same probes.
  const SolveResult figures =
      solve("database-figures " + (dir_ / "a" / "database.h5").string() + " --out " + (dir_ / "figs").string());
  ASSERT_EQ(figures.exitCode, 0) << figures.out;
  const json fj = json::parse(figures.out);
  EXPECT_EQ(fj["frames"].get<int>(), 10);
  EXPECT_EQ(fj["probes"], s["probes"]);
  EXPECT_EQ(fj["pressure_drop"]["samples"].get<int>(), 80);
  EXPECT_TRUE(fs::exists(dir_ / "figs" / "database_alpha_p.svg"));

  // rcfd-solve droplet-paths follows the spray through the same file's 10 frames of 5 ms.
  const std::string file = (dir_ / "a" / "database.h5").string();
  const SolveResult paths = solve("droplet-paths " + file + " --launches 3 --paths 8 --max-seconds 0.02 --heights 0.01,0.05");
  ASSERT_EQ(paths.exitCode, 0) << paths.out;
  const json pj = json::parse(paths.out);
  EXPECT_NEAR(pj["outlet"].get<double>() + pj["wall"].get<double>() + pj["airborne"].get<double>() +
                  pj["deposited"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(pj["heights"].size(), 2u);
  const SolveResult tooLong = solve("droplet-paths " + file + " --max-seconds 1", true);
  EXPECT_EQ(tooLong.exitCode, 2);
  EXPECT_NE(tooLong.out.find("/max_seconds"), std::string::npos) << tooLong.out;
}

TEST_F(DatabaseJob, TheVelocitySpreadIsWrittenWhenATracerEffectReadsItAndAddsUpToTheMean) {
  json scene = sceneDocument();
  scene["effects"] = json::array({"rolling_friction", "transport", "tracer_volume_fraction", "velocity_streams"});
  writeJob(scene, "streams.json");
  ASSERT_EQ(solve(run("s", "", "streams.json")).exitCode, 0);
  ASSERT_EQ(solve(run("plain")).exitCode, 0);
  // Without the effect, the database is as before: no spread datasets, and the same frames.
  rcfd::h5::File plain((dir_ / "plain" / "database.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  for (const auto& f : rcfd::kVelocitySpreadFields) EXPECT_FALSE(plain.exists(f.path)) << f.path;
  expectSameDatabase(dir_ / "s" / "database.h5", dir_ / "plain" / "database.h5");
  auto db = rcfd::FieldDatabase::open((dir_ / "s" / "database.h5").string(), rcfd::FrameStorage{0, true});
  ASSERT_TRUE(db->hasVelocitySpread());
  long moving = 0;
  for (int n = 0; n < db->frameCount(); ++n) {
    const auto f = db->frame(n);
    for (std::size_t c = 0; c < f->alpha_p.size(); ++c) {
      const double share = f->up_fraction[c];
      for (std::size_t d = 0; d < 3; ++d) {
        const double recombined = share * f->u_p_up[3 * c + d] + (1.0 - share) * f->u_p_down[3 * c + d];
        EXPECT_NEAR(recombined, f->u_p[3 * c + d], 1e-5 + 1e-5 * std::abs(f->u_p[3 * c + d])) << "frame " << n;
        EXPECT_GE(f->u_p_variance[3 * c + d], 0.0f);
      }
      if (f->alpha_p[c] == 0.0f && !neighbourVelocityRange(*f, db->grid(), c)) {
        EXPECT_EQ(share, 0.0);  // no particle volume in it or next to it
      }
      moving += f->u_p_variance[3 * c + 1] > 0.0f;
    }
  }
  EXPECT_GT(moving, 0);  // the settled bed still jiggles
}

TEST_F(DatabaseJob, StoppedAndResumedEqualsUninterrupted) {
  ASSERT_EQ(solve(run("a")).exitCode, 0);
  // Stop during sampling, then again later; resume the second time from the FIRST checkpoint, as if
  // the process had been killed after it: the frames written since must be cut back and redone.
  const SolveResult first = solve(run("b", "--stop-after-steps 300"));
  ASSERT_EQ(first.exitCode, 130);
  ASSERT_TRUE(fs::exists(dir_ / "b" / "checkpoint.h5"));
  EXPECT_FALSE(fs::exists(dir_ / "b" / "summary.json"));
  const int framesAtFirst = rcfd::FieldDatabase::open((dir_ / "b" / "database.h5").string())->frameCount();
  fs::copy_file(dir_ / "b" / "checkpoint.h5", dir_ / "first-checkpoint.h5");
  ASSERT_EQ(solve(run("b", "--stop-after-steps 100")).exitCode, 130);
  const int framesAtSecond = rcfd::FieldDatabase::open((dir_ / "b" / "database.h5").string())->frameCount();
  EXPECT_GT(framesAtSecond, framesAtFirst);
  fs::copy_file(dir_ / "first-checkpoint.h5", dir_ / "b" / "checkpoint.h5", fs::copy_options::overwrite_existing);
  ASSERT_EQ(solve(run("b")).exitCode, 0);
  EXPECT_EQ(summaryOf(dir_ / "a").dump(), summaryOf(dir_ / "b").dump());
  expectSameDatabase(dir_ / "a" / "database.h5", dir_ / "b" / "database.h5");
  EXPECT_FALSE(fs::exists(dir_ / "b" / "checkpoint.h5"));
}

// With the gas: a tiny prismatic bed (200 parcels, 1,440 cells) through ramp, warm-up and sampling;
// stopped during sampling and resumed, frames (u_G included), pressure drop and probe signals agree
// with the uninterrupted job's to 1e-6 (not bit for bit: see expectCloseDatabase).
/// A tiny prismatic bed with the gas (200 parcels, 1,440 cells) through ramp, warm-up, 15 ms of
/// sampling and 5 ms of reference.
json gasScene() {
  return json::parse(R"({
    "name": "database-gas-test",
    "apparatus": {"type": "prismatic_spouted_bed", "width": 0.06, "depth": 0.01, "height": 0.3,
                  "prism_angle_deg": 60, "inlet_width": 0.01},
    "grid": {"cell_size": 0.005},
    "gas": {"max_time_step": 5e-5},
    "particles": {},
    "process": {"gas_flow_rate": 2e-4, "atomisation_flow_rate": 1e-6, "bed_mass": 6.4e-4},
    "spray": {"nozzle_position": [0.0, 0.0, 0.005], "nozzle_diameter": 0.002,
              "spray_zone": {"apex": [0.0, 0.0, 0.005], "half_angle_deg": 30, "y_min": 0.005, "y_max": 0.04}},
    "dem": {"time_step": 1e-5, "coupling_interval": 5, "settle_time": 0.05, "ramp_time": 0.01, "warmup": 0.01,
            "sample_rate": 200, "probe_rate": 1000, "sample_duration": 0.015, "reference_duration": 0.005},
    "probes": [{"name": "spout", "position": [0.0, 0.02, 0.005]}],
    "effects": ["gas", "drag", "smoothing", "rolling_friction"],
    "outputs": {"svg": false}
  })");
}

TEST_F(DatabaseJob, GasJobStoppedAndResumedEqualsUninterrupted) {
  const json scene = gasScene();
  writeJob(scene, "gas.json");
  ASSERT_EQ(solve(run("a", "", "gas.json")).exitCode, 0);
  ASSERT_EQ(solve(run("b", "--stop-after-steps 450", "gas.json")).exitCode, 130);
  ASSERT_EQ(solve(run("b", "", "gas.json")).exitCode, 0);
  const json s = summaryOf(dir_ / "a");
  EXPECT_TRUE(s["gas"].get<bool>());
  EXPECT_EQ(s["effects"], json::array({"gas", "drag", "smoothing", "rolling_friction"}));
  EXPECT_EQ(s["frames"].get<int>(), 3);
  EXPECT_GT(s["pressure_drop"]["mean_pa"].get<double>(), 0.0);
  const json r = summaryOf(dir_ / "b");
  EXPECT_EQ(r["frames"], s["frames"]);
  EXPECT_EQ(r["steps"], s["steps"]);
  EXPECT_NEAR(r["pressure_drop"]["mean_pa"].get<double>(), s["pressure_drop"]["mean_pa"].get<double>(),
              1e-6 * s["pressure_drop"]["mean_pa"].get<double>());
  expectCloseDatabase(dir_ / "a" / "database.h5", dir_ / "b" / "database.h5", 1e-6);
  // The gas moves: u_G is not zero in the sampled frames.
  auto db = rcfd::FieldDatabase::open((dir_ / "a" / "database.h5").string());
  float largest = 0.0f;
  for (const float v : db->frame(2)->u_g) largest = std::max(largest, std::abs(v));
  EXPECT_GT(largest, 0.1f);
}

// dem.frame_alpha_p only changes what the frames record: the same simulation (the reference series bit
// for bit), frames whose alpha_P holds the same particle volume, but the parcels' own, unsmoothed, which
// leaves the cells the smoothing alone reaches empty.
TEST_F(DatabaseJob, TheFramesRecordTheParcelsOwnAlphaWhenAskedFromTheSameSimulation) {
  json scene = gasScene();
  writeJob(scene, "coupling.json");
  scene["dem"]["frame_alpha_p"] = "parcels";
  writeJob(scene, "parcels.json");
  ASSERT_EQ(solve(run("c", "", "coupling.json")).exitCode, 0);
  ASSERT_EQ(solve(run("p", "", "parcels.json")).exitCode, 0);
  rcfd::h5::File fc((dir_ / "c" / "database.h5").string(), rcfd::h5::File::Mode::ReadOnly),
      fp((dir_ / "p" / "database.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  for (const char* set : {"/reference/holdup/particles", "/reference/pressure_drop/pa", "/reference/probes/u_p_y"})
    EXPECT_EQ(fc.readDoubles(set), fp.readDoubles(set)) << set;
  auto dc = rcfd::FieldDatabase::open((dir_ / "c" / "database.h5").string());
  auto dp = rcfd::FieldDatabase::open((dir_ / "p" / "database.h5").string());
  ASSERT_EQ(dc->frameCount(), dp->frameCount());
  const auto& open = dc->fluidFraction();
  const double cellVolume = dc->grid().cellVolume();
  int sharper = 0;
  for (int n = 0; n < dc->frameCount(); ++n) {
    const auto c = dc->frame(n), p = dp->frame(n);
    EXPECT_EQ(c->u_g, p->u_g) << "frame " << n;
    double volumeC = 0.0, volumeP = 0.0;
    long occupiedC = 0, occupiedP = 0;
    for (std::size_t i = 0; i < open.size(); ++i) {
      volumeC += double(c->alpha_p[i]) * open[i] * cellVolume;
      volumeP += double(p->alpha_p[i]) * open[i] * cellVolume;
      occupiedC += c->alpha_p[i] > 0.0f;
      occupiedP += p->alpha_p[i] > 0.0f;
    }
    EXPECT_NEAR(volumeP, volumeC, 1e-5 * volumeC) << "frame " << n;
    EXPECT_LE(occupiedP, occupiedC) << "frame " << n;
    sharper += occupiedP < occupiedC;
  }
  EXPECT_GT(sharper, 0);
  EXPECT_EQ(json::parse(fp.readString("/scene"))["dem"]["frame_alpha_p"], "parcels");  // the database says which
}

// A scene that asks for the coverage gets the full simulation's own: the spray model on the parcels over
// the reference period, one value per parcel, books that close, stepped at the reference samples.
TEST_F(DatabaseJob, RecordsTheReferenceCoverageWhenTheSceneAsksForTheCoverage) {
  json scene = gasScene();
  scene["name"] = "database-coverage-test";
  scene["spray"]["parcels_per_s"] = 20000;
  scene["dem"]["reference_duration"] = 0.02;
  scene["effects"] = json::array({"gas", "drag", "smoothing", "rolling_friction", "tracer_volume_fraction", "spray",
                                  "deposition", "coverage"});
  writeJob(scene, "coverage.json");
  ASSERT_EQ(solve(run("a", "", "coverage.json")).exitCode, 0);
  const json s = summaryOf(dir_ / "a");
  const json& c = s["reference_coverage"];
  ASSERT_TRUE(c.is_object()) << s.dump(1);
  EXPECT_NEAR(c["duration_s"].get<double>(), 0.02, 1e-12);
  EXPECT_NEAR(c["dt_s"].get<double>(), 0.001, 1e-15);
  EXPECT_EQ(c["parcels"], s["particles"]);
  EXPECT_DOUBLE_EQ(c["particles_per_parcel"].get<double>(), s["particles_per_parcel"].get<double>());
  EXPECT_GT(c["deposited_fraction"].get<double>(), 0.0);
  rcfd::h5::File db((dir_ / "a" / "database.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  const auto droplets = db.readDoubles(rcfd::analysis::reference_layout::coverageDroplets);
  EXPECT_EQ(droplets.size(), s["particles"].get<std::size_t>());
  double collected = 0.0;
  for (const double n : droplets) {
    EXPECT_GE(n, 0.0);
    collected += n * s["particles_per_parcel"].get<double>();
  }
  const auto books = db.readDoubles(rcfd::analysis::reference_layout::coverageBalance);
  ASSERT_EQ(books.size(), 6u);
  EXPECT_NEAR(books[0], books[1] + books[2] + books[3] + books[4] + books[5], 1e-9 * books[0]);
  // Whole droplets on the parcels; what is deposited but not handed out waits in cells (< 1 each).
  EXPECT_LE(collected, books[1] + 1e-9);
  EXPECT_GT(collected, 0.0);
}

TEST_F(DatabaseJob, BadInputsExitTwoNamingTheField) {
  json scene = sceneDocument();
  scene["dem"]["sample_rate"] = 300.0;  // 166.7 DEM steps per frame
  writeJob(scene, "bad.json");
  SolveResult r = solve(run("c", "", "bad.json"), true);
  EXPECT_EQ(r.exitCode, 2) << r.out;
  EXPECT_NE(r.out.find("/dem/sample_rate"), std::string::npos) << r.out;
  scene = sceneDocument();
  scene["dem"]["probe_rate"] = 700.0;  // not a multiple of 200 Hz
  writeJob(scene, "bad2.json");
  r = solve(run("d", "", "bad2.json"), true);
  EXPECT_EQ(r.exitCode, 2) << r.out;
  EXPECT_NE(r.out.find("/dem/probe_rate"), std::string::npos) << r.out;
  // A checkpoint of another scene in the output directory is refused, not silently resumed.
  ASSERT_EQ(solve(run("e", "--stop-after-steps 5")).exitCode, 130);
  scene = sceneDocument();
  scene["dem"]["warmup"] = 0.02;
  writeJob(scene, "other.json");
  r = solve(run("e", "", "other.json"), true);
  EXPECT_EQ(r.exitCode, 2) << r.out;
  EXPECT_NE(r.out.find("checkpoint"), std::string::npos) << r.out;
}
