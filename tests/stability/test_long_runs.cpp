// Long runs (docs/stability.md, "Long runs"): an hour of spray at dt = 5 ms (720,000 steps) on a
// reduced grid in the default suite, free of drift in time and in every accumulator; ten hours behind
// RCFD_STABILITY_LONG=1 (the same reduced grid, 7.2 million steps), and ten hours on the quick database
// behind RCFD_STABILITY_QUICK_DB=path/to/database.h5 (a database job of examples/quick.json; about
// 0.4 x real time on two cores for its 20,000 tracers, RCFD_STABILITY_QUICK_TRACERS fewer).
#include <gtest/gtest.h>

#include <cstdlib>

#include "StabilityCases.hpp"
#include "core/Hdf5.hpp"

using namespace rcfd::stability;

namespace {

/// A 4 x 6 x 2 cm box of 1 cm cells, 64 tracers, every tracer and spray effect, 200 parcels/s.
json reducedScene() {
  json s = boxScene();
  s["name"] = "stability-long";
  s["apparatus"]["size"] = {0.04, 0.06, 0.02};
  s["process"]["bed_mass"] = 0.3 * 0.04 * 0.06 * 0.02 * 1040.0;
  s["rcfd"]["tracers"] = 64;
  s["spray"] = json::parse(R"({"nozzle_position": [0.0, 0.005, 0.01], "nozzle_diameter": 0.002,
      "parcels_per_s": 200, "spray_zone": {"apex": [0.0, 0.005, 0.01], "y_min": 0.01, "y_max": 0.04}})");
  s["probes"] = json::parse(R"([{"name": "centre", "position": [0.0, 0.03, 0.01]}])");
  return s;
}

/// alpha_P^rec steady in time (so its time average is known exactly) and varying in space; velocities
/// changing from frame to frame.
rcfd::FrameFunction steadyBed(const rcfd::CartesianGrid& grid) {
  return [grid](int n, double t, rcfd::FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      f.alpha_p[std::size_t(c)] = float(0.1 + 0.05 * ijk[0] + 0.02 * ijk[1]);
      f.u_p[3 * c] = float(0.3 * std::sin(6.0 * t + ijk[1]));
      f.u_p[3 * c + 1] = float(0.5 * std::cos(4.0 * t + ijk[0] + n));
      f.u_g[3 * c + 1] = float(3.0 + std::sin(5.0 * t));
    }
  };
}

/// Runs `hours` of spray on the reduced scene and checks time and accumulators.
void runReduced(double hours, double bound) {
  const json scene = reducedScene();
  const rcfd::CartesianGrid grid = sceneGrid(scene).grid;
  const fs::path dir = caseDirectory("long-" + std::to_string(int(hours)) + "h");
  writeDatabase(scene, dir / "db.h5", 40, 0.005, steadyBed(grid));
  json job = sprayJob(scene, dir / "db.h5", 3600.0 * hours);
  job["checkpoint_interval"] = 600.0;
  const Outcome o = runJob(job, dir, bound, 2);
  ASSERT_EQ(o.exitCode, 0) << o.describe();
  EXPECT_EQ(outcomeProblem(o, job, dir), "");
  const json s = json::parse(std::ifstream(dir / "out" / "summary.json"));
  // Time is the step count times dt, not a running sum: exactly the requested duration.
  const std::int64_t steps = std::llround(3600.0 * hours / 0.005);
  EXPECT_EQ(s["steps"].get<std::int64_t>(), steps);
  EXPECT_EQ(s["sim_time_s"].get<double>(), double(steps) * 0.005);
  rcfd::h5::File r((dir / "out" / "result.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  EXPECT_EQ(r.shape("/holdup/particles").at(0), hsize_t(steps));  // one sample per step, none lost
  // Injected from the integer parcel count: exactly 200 per second of the run.
  EXPECT_EQ(s["parcels"]["injected"].get<std::int64_t>(), std::llround(200.0 * 3600.0 * hours));
  // The steady alpha_P^rec averaged over every step is the frames' value in every cell, to float
  // rounding: a float accumulator would have drifted by 1e-3 after a million steps.
  const auto recurrence = r.readDoubles("/field_average/alpha_p_recurrence");
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    const double expected = double(float(0.1 + 0.05 * ijk[0] + 0.02 * ijk[1]));
    EXPECT_NEAR(recurrence[std::size_t(c)], expected, 1e-6) << "cell " << c;
  }
  EXPECT_EQ(s["field_average"]["samples"].get<std::int64_t>(), steps);
  // Stays: each completed stay counted once; their count and the histogram agree.
  std::int64_t histogram = 0;
  for (const auto& n : s["residence_time"]["histogram"]["counts"]) histogram += n.get<std::int64_t>();
  EXPECT_LE(histogram, s["residence_time"]["stays"].get<std::int64_t>());
  EXPECT_GT(s["residence_time"]["stays"].get<std::int64_t>(), 1000);
}

}  // namespace

TEST(LongRuns, AnHourAtFiveMillisecondsOnAReducedGridHasNoDriftInTimeOrAccumulators) { runReduced(1.0, 900.0); }

TEST(LongRuns, TenHoursAtFiveMillisecondsOnAReducedGrid) {
  if (!std::getenv("RCFD_STABILITY_LONG")) GTEST_SKIP() << "set RCFD_STABILITY_LONG=1 (about ten minutes)";
  runReduced(10.0, 7200.0);
}

// Ten hours of spray on the quick database (examples/quick.json, its own 20,000 tracers or
// RCFD_STABILITY_QUICK_TRACERS): the whole chain of the README's pipeline at 60 x its spray time.
TEST(LongRuns, TenHoursOfSprayOnTheQuickDatabase) {
  const char* database = std::getenv("RCFD_STABILITY_QUICK_DB");
  if (!database) GTEST_SKIP() << "set RCFD_STABILITY_QUICK_DB to a database of examples/quick.json";
  json scene = json::parse(std::ifstream(std::string(RCFD_SOURCE_DIR) + "/examples/quick.json"));
  if (const char* n = std::getenv("RCFD_STABILITY_QUICK_TRACERS")) scene["rcfd"]["tracers"] = std::atol(n);
  scene["outputs"]["svg"] = false;
  const fs::path dir = caseDirectory("long-quick");
  json job = sprayJob(scene, database, 36000.0);
  job["checkpoint_interval"] = 600.0;
  const Outcome o = runJob(job, dir, 12.0 * 3600.0, 2);
  ASSERT_EQ(o.exitCode, 0) << o.describe();
  EXPECT_EQ(outcomeProblem(o, job, dir), "");
  const json s = json::parse(std::ifstream(dir / "out" / "summary.json"));
  EXPECT_EQ(s["steps"].get<std::int64_t>(), 7200000);
  std::cerr << "ten hours on the quick database: " << s["wall_time_s"].get<double>() << " s, coverage mean "
            << s["coverage"]["mean"].get<double>() << ", deposited "
            << s["mass_balance"]["deposited_kg"].get<double>() << " kg\n";
}
