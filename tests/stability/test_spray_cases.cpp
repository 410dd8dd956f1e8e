// Hard cases of the spray stage, each a whole spray job through rcfd-solve (docs/stability.md,
// "Spray"). The efficiency itself is checked point by point over St in [0, 1e6], Re_m in [0, 1e5] and
// alpha_P in [0, 0.74] by DepositionEfficiency.AlwaysInUnitIntervalAndFinite (tests/spray); here the
// same extremes run through the parcels, the hand-out to the tracers, the books and Eq. (15).
#include <gtest/gtest.h>

#include <algorithm>

#include "StabilityCases.hpp"
#include "core/Hdf5.hpp"
#include "spray/Coverage.hpp"

using namespace rcfd::stability;

namespace {

constexpr double kBound = 120.0;

json summaryOf(const fs::path& dir) { return json::parse(std::ifstream(dir / "out" / "summary.json")); }

std::vector<double> dataset(const fs::path& dir, const std::string& name) {
  rcfd::h5::File f((dir / "out" / "result.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  return f.readDoubles(name);
}

/// Runs `scene` on the swaying spout (or `fill`) for `duration` and expects a clean exit 0.
json runClean(const std::string& name, const json& scene, double duration, rcfd::FrameFunction fill = {}) {
  const fs::path dir = caseDirectory(name);
  writeDatabase(scene, dir / "db.h5", 40, 0.005, std::move(fill));
  const json job = sprayJob(scene, dir / "db.h5", duration);
  const Outcome o = runJob(job, dir, kBound);
  EXPECT_EQ(o.exitCode, 0) << o.describe();
  EXPECT_EQ(outcomeProblem(o, job, dir), "");
  return o.exitCode == 0 ? summaryOf(dir) : json();
}

/// Runs `scene` and expects exit 2 naming `pointer`.
void expectRefused(const std::string& name, const json& scene, const std::string& pointer) {
  const fs::path dir = caseDirectory(name);
  writeDatabase(boxScene(), dir / "db.h5");  // the same grid; `scene` itself does not load
  const Outcome o = runJob(sprayJob(scene, dir / "db.h5", 0.2), dir, kBound);
  EXPECT_EQ(inputErrorProblem(o), "");
  EXPECT_NE(o.stderrText.find(pointer), std::string::npos) << o.stderrText;
}

double depositedFraction(const json& s) {
  return s["mass_balance"]["deposited_kg"].get<double>() / s["mass_balance"]["injected_kg"].get<double>();
}

}  // namespace

// St -> 0: droplets of 0.1 um follow the gas (St ~ 1e-5 per m/s of slip, lambda ~ St^3.2): almost
// nothing deposits, and 4e10 droplets per parcel keep the books closed.
TEST(SprayCases, StokesNumberNearZeroDepositsAlmostNothing) {
  json scene = boxScene();
  scene["spray"]["droplet_diameter"] = 1e-7;
  const json s = runClean("st-zero", scene, 0.5);
  ASSERT_TRUE(s.is_object());
  EXPECT_GT(s["parcels"]["droplets_per_parcel"].get<double>(), 1e10);
  EXPECT_LT(depositedFraction(s), 1e-4);  // the paper's 40 um droplets: about 0.3 on this bed
}

// St -> 1e6 (droplets of 1.5 mm and 10 t/m3 in 13 m/s of slip): lambda -> 1 and eta -> 1 wherever
// there are tracers; at most every droplet deposits, coverage saturates at 1.
TEST(SprayCases, StokesNumberOfAMillionDepositsAtMostEverything) {
  json scene = boxScene();
  scene["spray"]["droplet_diameter"] = 1.5e-3;
  scene["spray"]["droplet_density"] = 1e4;
  scene["spray"]["mass_rate"] = 1.0;  // 56,000 droplets/s, 14 per parcel
  const rcfd::CartesianGrid grid = sceneGrid(scene).grid;
  const auto spout = spoutFrames(grid);
  const json s = runClean("st-huge", scene, 0.5, [grid, spout](int n, double t, rcfd::FieldFrame& f) {
    spout(n, t, f);
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) f.u_g[3 * c + 1] = 13.0f;
  });
  ASSERT_TRUE(s.is_object());
  EXPECT_GT(depositedFraction(s), 0.5);
  EXPECT_LE(s["coverage"]["p90"].get<double>(), 1.0);
}

// Re_m -> 0: a gas 7,000 x as viscous as air (nu = 0.1 m2/s) makes Re_m ~ 1e-2 and St 7,000 x
// smaller; the free-flight drag (implicit) and the filter coefficient stay finite, and far less
// deposits than in air.
TEST(SprayCases, ModifiedReynoldsNumberNearZero) {
  json scene = boxScene();
  const json air = runClean("re-air", scene, 0.5);
  scene["gas"]["kinematic_viscosity"] = 0.1;
  const json s = runClean("re-zero", scene, 0.5);
  ASSERT_TRUE(s.is_object() && air.is_object());
  EXPECT_LT(depositedFraction(s), 0.05 * depositedFraction(air));
}

// No slip anywhere (u_G^rec = u_P^rec in every cell): Eq. (11) gives eta = 0, so not one droplet
// deposits, and the parcels ride the gas out.
TEST(SprayCases, ZeroRelativeVelocityDepositsNothing) {
  const json scene = boxScene();
  const rcfd::CartesianGrid grid = sceneGrid(scene).grid;
  const auto spout = spoutFrames(grid);
  const json s = runClean("no-slip", scene, 0.5, [grid, spout](int n, double t, rcfd::FieldFrame& f) {
    spout(n, t, f);
    // Particle volume everywhere, so that no cell's u_P is completed from its neighbours
    // (VelocityCompletion.hpp) and u_G = u_P holds in every cell.
    for (float& a : f.alpha_p) a = std::max(a, 1e-4f);
    f.u_g = f.u_p;
  });
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["mass_balance"]["deposited_kg"].get<double>(), 0.0);
  EXPECT_EQ(s["coverage"]["p90"].get<double>(), 0.0);
}

// parcels_per_s: 0 is refused by the schema (> 0); 1e9 is above the documented maximum 1e7 (the
// airborne parcels live in memory); more parcels than droplets would leave every parcel with less
// than one droplet, dropped at once as residual: refused naming the bound. The maximum itself runs.
TEST(SprayCases, ZeroAndEnormousParcelRatesAreRefusedAndTheLargestRuns) {
  json scene = boxScene();
  scene["spray"]["parcels_per_s"] = 0;
  expectRefused("parcels-zero", scene, "/spray/parcels_per_s");
  scene["spray"]["parcels_per_s"] = 1e9;
  expectRefused("parcels-enormous", scene, "/spray/parcels_per_s");
  scene["spray"]["parcels_per_s"] = 1e7;  // the default mass rate gives 2.5 million droplets/s
  expectRefused("parcels-above-droplets", scene, "/spray/parcels_per_s");
  scene["spray"]["mass_rate"] = 1e-3;  // 3e7 droplets/s: 3 per parcel
  scene["rcfd"]["tracers"] = 500;
  const json s = runClean("parcels-largest", scene, 0.1);
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["parcels"]["injected"].get<std::int64_t>(), 1000000);
}

// The largest droplets allowed are just below the particle diameter (f = (d_D / 2 d_P)^2 < 1/4);
// a droplet as large as the particle, and one so large that f > 1 (Eq. (15) would be NaN), are refused.
TEST(SprayCases, TheLargestDropletsAllowedRunAndLargerOnesAreRefused) {
  json scene = boxScene();
  scene["spray"]["droplet_diameter"] = 0.99 * 1.8e-3;
  scene["spray"]["mass_rate"] = 0.5;  // 150,000 droplets/s
  const json s = runClean("droplets-largest", scene, 0.5);
  ASSERT_TRUE(s.is_object());
  EXPECT_NEAR(s["coverage"]["f"].get<double>(), 0.99 * 0.99 / 4.0, 1e-12);
  scene["spray"]["droplet_diameter"] = 1.8e-3;
  expectRefused("droplets-as-large", scene, "/spray/droplet_diameter");
  scene["spray"]["droplet_diameter"] = 5e-3;
  expectRefused("droplets-larger", scene, "/spray/droplet_diameter");
}

// A hundred thousand droplets and more per tracer: the counts stay whole numbers, the books close and
// every tracer's coverage is Eq. (15) of its count, in [0, 1].
TEST(SprayCases, AHundredThousandDropletsPerTracerKeepEquation15) {
  json scene = boxScene();
  scene["apparatus"]["size"] = {0.02, 0.03, 0.01};
  scene["grid"]["cell_size"] = 0.005;
  scene["process"]["bed_mass"] = 0.5 * 0.02 * 0.03 * 0.01 * 1040.0;
  scene["rcfd"]["tracers"] = 100;
  scene["spray"] = json::parse(R"({"nozzle_position": [0.0, 0.002, 0.005], "nozzle_diameter": 0.002,
      "parcels_per_s": 20000, "mass_rate": 1e-3,
      "spray_zone": {"apex": [0.0, 0.002, 0.005], "y_min": 0.004, "y_max": 0.02}})");
  scene["probes"] = json::parse(R"([{"name": "centre", "position": [0.0, 0.015, 0.005]}])");
  const rcfd::CartesianGrid grid = sceneGrid(scene).grid;
  const fs::path dir = caseDirectory("droplets-per-tracer");
  writeDatabase(scene, dir / "db.h5", 40, 0.005, [grid](int n, double, rcfd::FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      f.alpha_p[std::size_t(c)] = 0.5f;
      f.u_p[3 * c] = float(0.2 * std::sin(double(n + c)));
      f.u_g[3 * c + 1] = 10.0f;
    }
  });
  const json job = sprayJob(scene, dir / "db.h5", 1.0);
  const Outcome o = runJob(job, dir, kBound);
  ASSERT_EQ(o.exitCode, 0) << o.describe();
  EXPECT_EQ(outcomeProblem(o, job, dir), "");
  const json s = summaryOf(dir);
  const double ppt = s["particles_per_tracer"].get<double>();
  const auto perParticle = dataset(dir, "/coverage/droplets_per_particle");
  const auto phi = dataset(dir, "/coverage/per_tracer");
  double most = 0.0;
  const double f = s["coverage"]["f"].get<double>();
  for (std::size_t i = 0; i < phi.size(); ++i) {
    const double droplets = perParticle[i] * ppt;
    most = std::max(most, droplets);
    EXPECT_NEAR(droplets, std::round(droplets), 1e-6 * droplets) << "whole droplets, tracer " << i;
    EXPECT_DOUBLE_EQ(phi[i], rcfd::coverage(perParticle[i], f)) << "tracer " << i;
  }
  EXPECT_GE(most, 1e5);
}

// Droplets of 0.1 um and 10 t/m3 at 1 kg/s: 5e10 droplets a parcel, more than 2^31 deposited in one
// cell in one step. The hand-out counts them in 64 bits and books every one.
TEST(SprayCases, BillionsOfDropletsInOneCellAndStepAreHandedOutAndBooked) {
  json scene = boxScene();
  scene["spray"]["droplet_diameter"] = 1e-7;
  scene["spray"]["droplet_density"] = 1e7;
  scene["spray"]["mass_rate"] = 1.0;
  const rcfd::CartesianGrid grid = sceneGrid(scene).grid;
  const auto spout = spoutFrames(grid);
  const json s = runClean("billions", scene, 0.3, [grid, spout](int n, double t, rcfd::FieldFrame& f) {
    spout(n, t, f);
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) f.u_g[3 * c + 1] = 20.0f;
  });
  ASSERT_TRUE(s.is_object());
  const double m = s["mass_balance"]["on_tracers_kg"].get<double>();
  const double dropletMass = 1e7 * std::numbers::pi / 6.0 * 1e-21;
  EXPECT_GT(m / dropletMass, 1e12);  // far more than an int32 counts
  EXPECT_GT(depositedFraction(s), 0.01);
}
