// The database job's parts that do not need the gas: the schedule and its input checks, the
// dominant frequency of a series, spray-zone stays (unit and an analytic free fall of DEM parcels
// through the zone) and the figures.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include "analysis/AlphaProfiles.hpp"
#include "analysis/DatabaseFigures.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "analysis/SeriesSpectrum.hpp"
#include "analysis/ZoneStays.hpp"
#include "scene/DatabaseSchedule.hpp"
#include "cfddem/CfdDemSimulation.hpp"
#include "cfddem/DemSystem.hpp"
#include "cfddem/ReferenceRecorder.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "jobs/DatabaseProgress.hpp"
#include "scene/SceneLoader.hpp"

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

json boxScene() {
  return json::parse(R"({
    "name": "database-parts",
    "apparatus": {"type": "box", "size": [0.1, 0.3, 0.04]},
    "grid": {"cell_size": 0.01},
    "gas": {},
    "particles": {"diameter": 0.002},
    "process": {"bed_mass": 0.01},
    "spray": {"nozzle_position": [0.0, 0.005, 0.02],
              "spray_zone": {"apex": [0.0, 0.0, 0.02], "half_angle_deg": 30, "y_min": 0.05, "y_max": 0.15}},
    "dem": {"time_step": 1e-5, "settle_time": 0.0, "ramp_time": 0.0, "warmup": 0.0, "sample_rate": 200,
            "probe_rate": 1000, "sample_duration": 0.02, "reference_duration": 0.21},
    "probes": [{"name": "centre", "position": [0.0, 0.1, 0.02]}],
    "effects": []
  })");
}

/// The InputError message of loading `scene` and building its schedule ("" if it is accepted).
std::string scheduleError(const json& scene) {
  try {
    rcfd::DatabaseSchedule::fromScene(rcfd::loadScene(scene));
  } catch (const rcfd::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DatabaseSchedule, WholeStepsOfTheQuickScene) {
  const rcfd::Scene s = rcfd::loadSceneFile(std::string(RCFD_SOURCE_DIR) + "/examples/quick.json");
  const auto p = rcfd::DatabaseSchedule::fromScene(s);
  // Read from the scene, so the expectations follow its time step.
  const double dt = s.dem.time_step;
  EXPECT_EQ(p.frameSteps, std::llround(0.005 / dt));
  EXPECT_EQ(p.sampleSteps, std::llround(0.001 / dt));
  EXPECT_EQ(p.frames, 400);  // 2 s at 200 Hz
  EXPECT_EQ(p.referenceSamples, 2000);
  EXPECT_EQ(p.rampSteps, std::llround(0.2 / dt));
  EXPECT_EQ(p.warmupSteps, std::llround(1.0 / dt));
  EXPECT_EQ(p.sampledSamples(), 2000);
  EXPECT_EQ(p.frameOffset(0), p.rampSteps + p.warmupSteps);
  EXPECT_EQ(p.endOffset(), p.frameOffset(0) + 3999 * p.sampleSteps);
  EXPECT_DOUBLE_EQ(p.flowFactor(0), 0.0);
  EXPECT_DOUBLE_EQ(p.flowFactor(p.rampSteps / 4), 0.25);
  EXPECT_DOUBLE_EQ(p.flowFactor(p.rampSteps), 1.0);
  EXPECT_DOUBLE_EQ(p.flowFactor(10 * p.rampSteps), 1.0);
}

TEST(DatabaseProgress, PhasesJoinUpAndNameTheirOwnFraction) {
  const rcfd::Scene s = rcfd::loadSceneFile(std::string(RCFD_SOURCE_DIR) + "/examples/quick.json");
  const auto plan = rcfd::DatabaseSchedule::fromScene(s);
  const rcfd::CfdDemSimulation sim(s, 1);
  const rcfd::DatabaseProgress w(plan, s.dem.settle_time, rcfd::parcelsForBedMass(s), sim.fillFallSteps(),
                                 sim.grid().cellCount(), sim.hasGas());
  EXPECT_EQ(w.fill(0.0), 0.0);
  EXPECT_DOUBLE_EQ(w.fill(1.0), w.settle(0.0));
  EXPECT_DOUBLE_EQ(w.settle(1.0), w.coupled(0));
  EXPECT_DOUBLE_EQ(w.coupled(plan.endOffset()), 1.0);
  EXPECT_GT(w.fill(0.5), w.fill(0.25));
  EXPECT_GT(w.settle(0.5), w.settle(0.25));
  double last = 0.0;
  for (std::int64_t k = 0; k <= 100; ++k) {
    const double f = w.coupled(plan.endOffset() * k / 100);
    EXPECT_GT(f, last - 1e-15);
    last = f;
  }
  // The coupled steps cost the same throughout: equal steps, equal fractions.
  EXPECT_NEAR(w.coupled(plan.rampSteps) - w.coupled(0), w.coupled(2 * plan.rampSteps) - w.coupled(plan.rampSteps), 1e-12);

  EXPECT_STREQ(rcfd::coupledPhase(plan, 0), "ramp");
  EXPECT_DOUBLE_EQ(rcfd::coupledPhaseFraction(plan, 0), 0.0);
  EXPECT_DOUBLE_EQ(rcfd::coupledPhaseFraction(plan, plan.rampSteps / 2), 0.5);
  EXPECT_STREQ(rcfd::coupledPhase(plan, plan.rampSteps), "warmup");
  EXPECT_DOUBLE_EQ(rcfd::coupledPhaseFraction(plan, plan.rampSteps), 0.0);
  EXPECT_DOUBLE_EQ(rcfd::coupledPhaseFraction(plan, plan.rampSteps + plan.warmupSteps / 4), 0.25);
  const std::int64_t sampled = plan.frameOffset(plan.frames) - plan.frameOffset(0);
  EXPECT_STREQ(rcfd::coupledPhase(plan, plan.frameOffset(0)), "sample");
  EXPECT_DOUBLE_EQ(rcfd::coupledPhaseFraction(plan, plan.frameOffset(0) + sampled / 2), 0.5);
  EXPECT_STREQ(rcfd::coupledPhase(plan, plan.frameOffset(plan.frames)), "reference");
  EXPECT_DOUBLE_EQ(rcfd::coupledPhaseFraction(plan, plan.frameOffset(plan.frames)), 0.0);
  EXPECT_DOUBLE_EQ(rcfd::coupledPhaseFraction(plan, plan.endOffset()), 1.0);
}

TEST(DatabaseSchedule, RefusesRatesThatMissDemStepsNamingTheField) {
  json s = boxScene();
  EXPECT_EQ(scheduleError(s), "");
  s["dem"]["sample_rate"] = 300;  // 333.3 DEM steps per frame
  std::string e = scheduleError(s);
  EXPECT_NE(e.find("/dem/sample_rate"), std::string::npos) << e;
  EXPECT_NE(e.find("whole number"), std::string::npos) << e;
  s = boxScene();
  s["dem"]["probe_rate"] = 500.0 / 0.7;  // divides no DEM step, and not a multiple of 200 Hz
  e = scheduleError(s);
  EXPECT_NE(e.find("/dem/probe_rate"), std::string::npos) << e;
  s = boxScene();
  s["dem"]["probe_rate"] = 250;  // 400 DEM steps, but 1.25 samples per frame
  e = scheduleError(s);
  EXPECT_NE(e.find("/dem/probe_rate"), std::string::npos) << e;
  EXPECT_NE(e.find("probe_rate / sample_rate"), std::string::npos) << e;
  s = boxScene();
  s["dem"]["sample_duration"] = 0.0125;  // 2.5 frames
  e = scheduleError(s);
  EXPECT_NE(e.find("/dem/sample_duration"), std::string::npos) << e;
  s["dem"]["sample_duration"] = 0.01;  // 2 frames: Eq. (8) needs 3
  e = scheduleError(s);
  EXPECT_NE(e.find("/dem/sample_duration"), std::string::npos) << e;
  s = boxScene();
  s["dem"]["reference_duration"] = 0.0105;
  e = scheduleError(s);
  EXPECT_NE(e.find("/dem/reference_duration"), std::string::npos) << e;
  s["dem"]["ramp_time"] = -1;  // the schema's minimum
  EXPECT_THROW(rcfd::loadScene(s), rcfd::InputError);
}

TEST(SeriesSpectrum, FindsTheFrequencyOfANoisyDriftingSine) {
  const double dt = 1e-3, f = 7.3, amplitude = 40.0, noise = 60.0;
  const int n = 4000;  // 4 s: resolution 0.25 Hz
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss(0.0, noise);
  std::vector<double> x(n);
  for (int i = 0; i < n; ++i) {
    const double t = i * dt;
    x[std::size_t(i)] = 1200.0 + 150.0 * t + amplitude * std::sin(2 * std::numbers::pi * f * t + 0.4) + gauss(rng);
  }
  const auto s = rcfd::analysis::seriesSpectrum(x, dt);
  ASSERT_TRUE(s.dominantFrequency.has_value());
  EXPECT_DOUBLE_EQ(s.resolution, 0.25);
  EXPECT_LE(std::abs(*s.dominantFrequency - f), s.resolution) << *s.dominantFrequency;
  EXPECT_NEAR(s.mean, 1200.0 + 150.0 * 0.5 * (n - 1) * dt, 3.0);
  // Population std of drift (150 * 4 / sqrt(12)), sine and noise together.
  const double expected = std::sqrt(std::pow(150.0 * 4.0, 2) / 12.0 + amplitude * amplitude / 2 + noise * noise);
  EXPECT_NEAR(s.std, expected, 0.03 * expected);
  // The drift is removed exactly: a straight line detrends to round-off.
  std::vector<double> line(50);
  for (std::size_t i = 0; i < line.size(); ++i) line[i] = -3.0 + 0.25 * double(i);
  for (const double v : rcfd::analysis::detrended(line)) EXPECT_NEAR(v, 0.0, 1e-12);
}

TEST(SeriesSpectrum, ConstantSeriesHasNoDominantFrequencyAndBadInputIsRefused) {
  const auto s = rcfd::analysis::seriesSpectrum(std::vector<double>(100, 3.5), 0.01);
  EXPECT_FALSE(s.dominantFrequency.has_value());
  EXPECT_DOUBLE_EQ(s.mean, 3.5);
  EXPECT_DOUBLE_EQ(s.std, 0.0);
  EXPECT_FALSE(rcfd::analysis::seriesSpectrum(std::vector<double>(50, 0.0), 0.01).dominantFrequency);
  std::vector<double> ramp(64);
  for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = 2.0 + 0.5 * double(i);
  EXPECT_FALSE(rcfd::analysis::seriesSpectrum(ramp, 0.01).dominantFrequency);  // a pure drift
  EXPECT_THROW(rcfd::analysis::seriesSpectrum({1, 2, 3}, 0.01), rcfd::InputError);
  EXPECT_THROW(rcfd::analysis::seriesSpectrum({1, 2, 3, 4}, 0.0), rcfd::InputError);
  EXPECT_THROW(rcfd::analysis::seriesSpectrum({1, 2, std::nan(""), 4}, 0.1), rcfd::InputError);
}

TEST(ZoneStays, CountsCompletedStaysOnlyAndSurvivesACheckpoint) {
  rcfd::ZoneStays z(4);
  z.startInside(3);  // inside from the start: its stay is never counted
  // Member 0: in at 2..4 (out at 5): 3 samples. Member 1: in 1, out 2: 1 sample; in again 6..
  // (open at the end: censored). Member 2: in at 0 before countFrom = 1: not counted. Member 3:
  // inside from the start until 3: not counted.
  const std::vector<std::vector<int>> inside = {{0, 0, 1, 1}, {0, 1, 1, 1}, {1, 0, 1, 1}, {1, 0, 0, 0},
                                                {1, 0, 0, 0}, {0, 0, 0, 0}, {0, 1, 0, 0}};
  std::vector<std::int64_t> all;
  for (std::int64_t step = 0; step < std::int64_t(inside.size()); ++step) {
    std::vector<std::int64_t> done;
    for (std::size_t m = 0; m < 4; ++m) {
      const auto d = z.observe(m, inside[std::size_t(step)][m] != 0, step, 1);
      if (d >= 0) done.push_back(d);
    }
    z.addDurations(done);
    all.insert(all.end(), done.begin(), done.end());
  }
  std::sort(all.begin(), all.end());
  EXPECT_EQ(all, (std::vector<std::int64_t>{1, 3}));
  const auto st = z.statistics(0.01, 3);
  EXPECT_EQ(st.stays, 2);
  EXPECT_EQ(st.censored, 1);
  EXPECT_DOUBLE_EQ(st.mean_s, 0.02);
  EXPECT_DOUBLE_EQ(st.median_s, 0.01);
  EXPECT_EQ(z.durations(0.01), (std::vector<double>{0.01, 0.03}));
  const std::string path = (fs::temp_directory_path() / ("zone-stays-" + std::to_string(::getpid()) + ".h5")).string();
  {
    rcfd::h5::File f(path, rcfd::h5::File::Mode::Create);
    z.save(f, "/z");
  }
  rcfd::ZoneStays back;
  back.load(rcfd::h5::File(path, rcfd::h5::File::Mode::ReadOnly), "/z");
  EXPECT_EQ(back.durationCounts(), z.durationCounts());
  EXPECT_EQ(back.open(), 1);
  EXPECT_EQ(back.observe(1, false, 9, 1), 3);  // the open stay (entered at 6) ends after resume
  fs::remove(path);
}

/// Parcels at rest at (x, 0.25 m, 0.02 m) for each x in the box scene, about to fall through its
/// spray-zone cone (half-angle 30 deg, y 0.05-0.15 m).
struct FallingParcels {
  explicit FallingParcels(const std::vector<double>& xs) {
    for (const double x : xs) dem.addParticle(Eigen::Vector3d(x, y0, 0.02));
  }
  static constexpr double y0 = 0.25;
  const rcfd::Scene scene = rcfd::loadScene(boxScene());
  const rcfd::Apparatus box{scene.apparatus};
  const rcfd::CartesianGrid grid = rcfd::makeGrid(box, scene.grid);
  rcfd::DemSystem dem{rcfd::DemMaterial::fromScene(scene), rcfd::DemWalls::box(box.lowerCorner(), box.upperCorner()),
                      rcfd::DemSystem::settingsFromScene(scene)};
};

// Parcels released at rest fall through the spray-zone cone: each stay lasts from crossing y_max
// (or the cone's side) to crossing y_min, t = sqrt(2 h / g) at each height; the recorder sampled at
// 1 kHz must find every duration within one sample, and the holdup at each sample exactly.
TEST(ReferenceRecorder, FreeFallThroughTheSprayZoneGivesTheKinematicStays) {
  const std::vector<double> xs = {-0.02, -0.005, 0.0, 0.01, 0.035, 0.045};
  FallingParcels fall(xs);
  const rcfd::Scene& scene = fall.scene;
  const rcfd::CartesianGrid& grid = fall.grid;
  rcfd::DemSystem& dem = fall.dem;
  const double y0 = FallingParcels::y0, g = 9.81, tanA = std::tan(30.0 * std::numbers::pi / 180.0);
  const auto p = rcfd::DatabaseSchedule::fromScene(scene);
  rcfd::ReferenceRecorder rec(scene, grid, xs.size(), p.sampleDt(), 0);
  const std::vector<Eigen::Vector3d> noVelocity(std::size_t(grid.cellCount()), Eigen::Vector3d::Zero());
  const std::int64_t samples = 210;  // 0.21 s: before the parcels reach the floor at 0.226 s
  auto fallTime = [&](double y) { return std::sqrt(2.0 * (y0 - y) / g); };
  for (std::int64_t s = 0; s < samples; ++s) {
    rec.record(noVelocity, 0.0, dem.particles());
    dem.run(p.sampleSteps);
  }
  std::vector<double> expected;
  for (const double x : xs) {
    // Every release point is inside the cone at y_max (radius 0.087 m); the outer ones leave through
    // the cone's side, where its radius equals |x|.
    const double top = 0.15, bottom = std::max(0.05, std::abs(x) / tanA);
    if (bottom < top) expected.push_back(fallTime(bottom) - fallTime(top));
  }
  std::sort(expected.begin(), expected.end());
  const std::vector<double> got = rec.stays().durations(p.sampleDt());
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], expected[i], p.sampleDt()) << i;
  // Holdup: parcels inside at each sample time, from the analytic positions.
  ASSERT_EQ(rec.holdupParcels().size(), std::size_t(samples));
  for (std::int64_t s = 0; s < samples; ++s) {
    const double t = double(s) * p.sampleDt(), y = y0 - 0.5 * g * t * t;
    std::int64_t in = 0;
    for (const double x : xs) in += (y >= 0.05 && y <= 0.15 && std::abs(x) <= y * tanA);
    EXPECT_EQ(rec.holdupParcels()[std::size_t(s)], in) << "sample " << s;
  }
  const json sum = rec.summary(p.dtRec(), 10);
  EXPECT_EQ(sum["residence_time"]["stays"].get<int>(), int(expected.size()));
  EXPECT_EQ(sum["residence_time"]["censored"].get<int>(), 0);
  EXPECT_TRUE(sum["pressure_drop"]["dominant_frequency_hz"].is_null());
  EXPECT_DOUBLE_EQ(sum["pressure_drop"]["mean_pa"].get<double>(), 0.0);
}

// The sampled period (the frames') is counted as the reference period is: one fall recorded by a
// recorder whose reference period starts at once and by one whose sampled period holds the whole fall
// gives the same stays and holdup; they survive a checkpoint, reach the database file in the reference
// layout, and compared with themselves differ by nothing.
TEST(ReferenceRecorder, TheSampledPeriodIsCountedAsTheReferencePeriodIs) {
  const std::vector<double> xs = {-0.02, -0.005, 0.0, 0.01, 0.035, 0.045};
  FallingParcels fall(xs);
  const rcfd::Scene& scene = fall.scene;
  const rcfd::CartesianGrid& grid = fall.grid;
  rcfd::DemSystem& dem = fall.dem;
  const auto p = rcfd::DatabaseSchedule::fromScene(scene);
  const std::int64_t samples = 210;
  rcfd::ReferenceRecorder reference(scene, grid, xs.size(), p.sampleDt(), 0);
  rcfd::ReferenceRecorder sampled(scene, grid, xs.size(), p.sampleDt(), samples);
  const std::vector<Eigen::Vector3d> noVelocity(std::size_t(grid.cellCount()), Eigen::Vector3d::Zero());
  const std::string path = (fs::temp_directory_path() / ("sampled-period-" + std::to_string(::getpid()) + ".h5")).string();
  for (std::int64_t s = 0; s <= samples; ++s) {
    reference.record(noVelocity, 0.0, dem.particles());
    sampled.record(noVelocity, 0.0, dem.particles());
    if (s == samples / 2) {  // a checkpoint halfway through the sampled period
      {
        rcfd::h5::File f(path, rcfd::h5::File::Mode::Create);
        sampled.save(f, "/reference");
      }
      rcfd::ReferenceRecorder resumed(scene, grid, xs.size(), p.sampleDt(), samples);
      resumed.load(rcfd::h5::File(path, rcfd::h5::File::Mode::ReadOnly), "/reference");
      EXPECT_EQ(resumed.sampledHoldupParcels(), sampled.sampledHoldupParcels());
      EXPECT_EQ(resumed.sampledStays().open(), sampled.sampledStays().open());
    }
    dem.run(p.sampleSteps);
  }
  ASSERT_TRUE(sampled.sampledPeriodRecorded());
  EXPECT_FALSE(reference.sampledPeriodRecorded());  // no sampled period
  const auto expectedStays = reference.stays().durations(p.sampleDt());
  ASSERT_EQ(expectedStays.size(), xs.size());  // every parcel falls through the zone
  EXPECT_EQ(sampled.sampledStays().durations(p.sampleDt()), expectedStays);
  EXPECT_EQ(sampled.sampledHoldupParcels(),
            std::vector<std::int64_t>(reference.holdupParcels().begin(), reference.holdupParcels().end() - 1));
  EXPECT_TRUE(sampled.stays().durations(p.sampleDt()).empty());
  {
    rcfd::h5::File db(path, rcfd::h5::File::Mode::Create);
    sampled.write(db);
  }
  const auto read = rcfd::analysis::readReferenceStatistics(path);
  ASSERT_TRUE(read.sampledPeriod);
  EXPECT_EQ(read.sampledPeriod->durations, expectedStays);
  EXPECT_DOUBLE_EQ(read.sampledPeriod->members, double(xs.size()));
  EXPECT_NEAR(read.sampledPeriod->recordedPeriod(), double(samples) * p.sampleDt(), 1e-12);
  ASSERT_EQ(read.sampledPeriod->holdup.size(), std::size_t(samples));
  // The same stays seen as a run's step counts on the recorder's lattice: no difference at all.
  double holdupMean = 0.0;
  for (const auto h : sampled.sampledHoldupParcels()) holdupMean += double(h) / double(samples);
  const json c = rcfd::analysis::compareWithPeriod(*read.sampledPeriod, reference.stays().durationCounts(), p.sampleDt(),
                                                   double(xs.size()), double(samples) * p.sampleDt(), holdupMean, 0.0);
  EXPECT_NEAR(c["holdup_relative_error"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(c["ks_distance"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(c["mean_relative_error"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(c["crossing_rate_relative_error"].get<double>(), 0.0, 1e-12);
  // The summary compares the two periods (the reference period: one sample, every parcel below the zone).
  const json periods = sampled.summary(p.dtRec(), 10)["periods"];
  ASSERT_TRUE(periods.is_object());
  EXPECT_NEAR(periods["sampled_period_holdup_mean"].get<double>(), holdupMean * sampled.particlesPerParcel(), 1e-9);
  EXPECT_DOUBLE_EQ(periods["reference_period_holdup_mean"].get<double>(), 0.0);
  EXPECT_TRUE(periods["holdup_relative_difference"].is_null());
  fs::remove(path);
}

TEST(DatabaseFigures, SnapshotsTimeAverageAndPressureDrop) {
  const rcfd::Scene scene = rcfd::loadScene(boxScene());
  const rcfd::Apparatus box(scene.apparatus);
  const rcfd::CartesianGrid grid = rcfd::makeGrid(box, scene.grid);
  const auto open = rcfd::openFractions(box, grid);
  const std::vector<float> fluid(open.begin(), open.end());
  // alpha_P = 0.6 below a bed surface that moves with the frame, else 0.
  auto db = rcfd::makeAnalyticDatabase(grid, fluid, 0.005, 9, [&](int n, double, rcfd::FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      f.alpha_p[std::size_t(c)] = ijk[1] < 5 + n ? 0.6f : 0.0f;
    }
  });
  const auto mean = rcfd::analysis::meanAlphaP(*db);
  // A stop request is asked before every frame (the results of a long database job read minutes).
  int polls = 0;
  EXPECT_THROW(rcfd::analysis::meanAlphaP(*db, [&] { return ++polls > 2; }), rcfd::Cancelled);
  EXPECT_EQ(polls, 3);
  // Row j is filled in the frames n >= j - 4 of 0..8: 9 - max(0, j - 4) of the 9 frames.
  for (int j = 0; j < grid.shape[1]; ++j) {
    const double filled = std::clamp(double(9 - std::max(0, j - 4)), 0.0, 9.0) / 9.0;
    EXPECT_NEAR(mean[std::size_t(grid.flatIndex(2, j, 1))], 0.6 * filled, 1e-6) << j;
  }
  EXPECT_EQ(rcfd::analysis::snapshotFrames(9, 4), (std::vector<int>{0, 3, 5, 8}));
  EXPECT_EQ(rcfd::analysis::snapshotFrames(2, 4), (std::vector<int>{0, 1}));
  const fs::path dir = fs::temp_directory_path() / ("db-figures-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  rcfd::analysis::PressureDropSeries dp{{100, 120, 90, 110, 100}, 0.001, 0.0, 2.5};
  const auto names = rcfd::analysis::writeDatabaseFigures(scene, *db, dp, dir.string());
  ASSERT_EQ(names, (std::vector<std::string>{"database_alpha_p.svg", "database_pressure_drop.svg"}));
  std::stringstream a, b;
  a << std::ifstream(dir / names[0]).rdbuf();
  b << std::ifstream(dir / names[1]).rdbuf();
  EXPECT_NE(a.str().find("time average"), std::string::npos);
  EXPECT_NE(a.str().find("t = 0.040 s"), std::string::npos);  // the last snapshot, frame 8
  EXPECT_NE(b.str().find("2.50 Hz"), std::string::npos);
  EXPECT_NE(b.str().find("<polyline"), std::string::npos);
  fs::remove_all(dir);
}

TEST(AlphaProfiles, MidPlaneAndOpenVolumeWeightedDepthMeanAcrossX) {
  const rcfd::Scene scene = rcfd::loadScene(boxScene());
  const rcfd::Apparatus box(scene.apparatus);
  const rcfd::CartesianGrid grid = rcfd::makeGrid(box, scene.grid);
  ASSERT_EQ(grid.shape[2], 4);
  // Column i = 0 closed on the mid-plane layer (k = 2): not in the profile; column i = 1 half open
  // in its first layer: weighted by it in the depth mean.
  std::vector<float> fluid(std::size_t(grid.cellCount()), 1.0f);
  for (int j = 0; j < grid.shape[1]; ++j) {
    fluid[std::size_t(grid.flatIndex(0, j, 2))] = 0.0f;
    fluid[std::size_t(grid.flatIndex(1, j, 0))] = 0.5f;
  }
  auto db = rcfd::makeAnalyticDatabase(grid, fluid, 0.005, 3, [](int, double, rcfd::FieldFrame&) {});
  std::vector<double> alpha(std::size_t(grid.cellCount()));
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    alpha[std::size_t(c)] = 0.1 * (ijk[2] + 1) + 0.01 * ijk[0];
  }
  const double y = grid.cellCenter(0, 10, 0).y();
  const auto profiles = rcfd::analysis::alphaProfiles(scene, *db, alpha, {y + 0.002, 10.0});
  ASSERT_EQ(profiles.size(), 1u);  // 10 m is above the grid
  EXPECT_DOUBLE_EQ(profiles[0].y, y);
  const auto& cells = profiles[0].cells;
  ASSERT_EQ(int(cells.size()), grid.shape[0] - 1);
  EXPECT_DOUBLE_EQ(cells[0].x, grid.cellCenter(1, 10, 2).x());
  EXPECT_NEAR(cells[0].alphaMid, 0.31, 1e-12);
  EXPECT_NEAR(cells[0].alphaDepth, (0.5 * 0.11 + 0.21 + 0.31 + 0.41) / 3.5, 1e-12);
  EXPECT_DOUBLE_EQ(cells[0].openMid, 1.0);
  EXPECT_NEAR(cells[4].alphaMid, 0.35, 1e-12);    // column i = 5
  EXPECT_NEAR(cells[4].alphaDepth, 0.30, 1e-12);  // the plain mean of 0.15 .. 0.45
  const fs::path dir = fs::temp_directory_path() / ("alpha-profiles-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  EXPECT_EQ(rcfd::analysis::writeAlphaProfileFigure(profiles, dir.string()), "database_alpha_p_profiles.svg");
  std::stringstream svg;
  svg << std::ifstream(dir / "database_alpha_p_profiles.svg").rdbuf();
  EXPECT_NE(svg.str().find("<polyline"), std::string::npos);
  EXPECT_NE(svg.str().find("y = 0.1050 m"), std::string::npos);
  fs::remove_all(dir);
}
