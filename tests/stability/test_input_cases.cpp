// Hard inputs (docs/stability.md, "Input"): databases whose frames hold NaN, infinities or volume
// fractions outside [0, 1] are refused naming the frame and the dataset, whether the frames are loaded
// at open or through the frame cache; grids one cell deep or one cell wide run every job kind.
#include <gtest/gtest.h>

#include <limits>

#include "StabilityCases.hpp"

using namespace rcfd::stability;

namespace {

constexpr double kBound = 300.0;

}  // namespace

TEST(InputCases, BadValuesInADatabaseFrameAreRefusedNamingTheFrameAndTheDataset) {
  const json scene = boxScene();
  const rcfd::CartesianGrid grid = sceneGrid(scene).grid;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  struct Bad {
    const char* dataset;
    int components;
    float value;
  };
  const Bad cases[] = {{"/frames/alpha_p", 1, nan},   {"/frames/alpha_p", 1, inf},  {"/frames/alpha_p", 1, -inf},
                       {"/frames/alpha_p", 1, -0.01f}, {"/frames/alpha_p", 1, 1.5f}, {"/frames/u_p", 3, nan},
                       {"/frames/u_g", 3, inf}};
  int index = 0;
  for (const Bad& bad : cases) {
    for (const bool cached : {false, true}) {
      SCOPED_TRACE(std::string(bad.dataset) + " = " + std::to_string(bad.value) + (cached ? ", frame cache" : ""));
      const fs::path dir = caseDirectory("bad-frame-" + std::to_string(index++));
      json s = scene;
      if (cached) s["rcfd"]["frame_cache_bytes"] = 1 << 20;
      writeDatabase(s, dir / "db.h5");
      // Frame 7, cell (3, 4, 1), its y component for the vectors.
      const hsize_t cell = hsize_t(grid.flatIndex(3, 4, 1));
      pokeFloat(dir / "db.h5", bad.dataset, hsize_t(7 * grid.cellCount() + cell) * bad.components + (bad.components - 1),
                bad.value);
      const Outcome o = runJob(sprayJob(s, dir / "db.h5", 0.2), dir, kBound);
      EXPECT_EQ(inputErrorProblem(o), "");
      EXPECT_NE(o.stderrText.find(bad.dataset), std::string::npos) << o.stderrText;
      EXPECT_NE(o.stderrText.find("frame 7, cell (3, 4, 1)"), std::string::npos) << o.stderrText;
    }
  }
}

namespace {

/// A database job on `scene`, then a spray job and a calibration on its database; each must end
/// cleanly.
void runEveryKind(const std::string& name, json scene) {
  const fs::path dir = caseDirectory(name);
  const json database = {{"kind", "database"}, {"scene", scene}, {"seed", 5}};
  const Outcome db = runJob(database, dir / "database", kBound);
  ASSERT_EQ(db.exitCode, 0) << db.describe();
  EXPECT_EQ(outcomeProblem(db, database, dir / "database"), "");
  const fs::path file = dir / "database" / "out" / "database.h5";
  scene["rcfd"] = {{"dt", 0.005}, {"tracers", 300}, {"d0", 5e-4}};
  scene["effects"] = allTracerEffects();
  const json spray = sprayJob(scene, file, 0.3);
  const Outcome sp = runJob(spray, dir / "spray", kBound);
  EXPECT_EQ(sp.exitCode, 0) << sp.describe();
  EXPECT_EQ(outcomeProblem(sp, spray, dir / "spray"), "");
  const json calibration = {{"kind", "calibration"}, {"scene", scene},      {"database", file.string()},
                            {"duration", 0.2},       {"discard", 0.05},     {"d0_values", {0.0, 5e-4}},
                            {"seed", 2}};
  const Outcome ca = runJob(calibration, dir / "calibration", kBound);
  EXPECT_EQ(ca.exitCode, 0) << ca.describe();
  EXPECT_EQ(outcomeProblem(ca, calibration, dir / "calibration"), "");
}

/// A 6 x 10 x 1 cm prism with gas; the DEM fills it and the gas runs through ramp, warm-up and sampling.
json thinPrism() {
  return json::parse(R"({
    "name": "stability-thin",
    "apparatus": {"type": "prismatic_spouted_bed", "width": 0.06, "depth": 0.01, "height": 0.3,
                  "prism_angle_deg": 60, "inlet_width": 0.01},
    "grid": {"cell_size": 0.005},
    "gas": {"max_time_step": 5e-5},
    "particles": {},
    "process": {"gas_flow_rate": 2e-4, "atomisation_flow_rate": 1e-6, "bed_mass": 6.4e-4},
    "spray": {"nozzle_position": [0.0, 0.0, 0.005], "nozzle_diameter": 0.002, "parcels_per_s": 2000,
              "spray_zone": {"apex": [0.0, 0.0, 0.005], "half_angle_deg": 30, "y_min": 0.005, "y_max": 0.04}},
    "dem": {"time_step": 1e-5, "coupling_interval": 5, "settle_time": 0.05, "ramp_time": 0.01, "warmup": 0.01,
            "sample_rate": 200, "probe_rate": 1000, "sample_duration": 0.05, "reference_duration": 0.02},
    "probes": [{"name": "spout", "position": [0.0, 0.02, 0.005]}],
    "effects": ["gas", "drag", "smoothing", "rolling_friction"],
    "outputs": {"svg": false}
  })");
}

}  // namespace

// One cell deep: cells of 5 x 5 x 8 mm over a depth of 1 cm (8 mm rounds to one 1 cm layer).
TEST(InputCases, AOneCellDeepGridRunsEveryJobKind) {
  json scene = thinPrism();
  scene["grid"]["cell_size"] = {0.005, 0.005, 0.008};
  ASSERT_EQ(sceneGrid(scene).grid.shape[2], 1);
  runEveryKind("one-deep", scene);
}

// One cell deep whose cell is the whole depth (10 mm), as pseudo-2D cases of other codes are written.
TEST(InputCases, ACellAsDeepAsTheApparatusRunsEveryJobKind) {
  json scene = thinPrism();
  scene["grid"]["cell_size"] = {0.005, 0.005, 0.01};
  const auto grid = sceneGrid(scene).grid;
  ASSERT_EQ(grid.shape[2], 1);
  EXPECT_DOUBLE_EQ(grid.spacing.z(), 0.01);
  runEveryKind("cell-as-deep", scene);
}

// One cell wide: a box 1 cm across with 8 mm cells (a box has no gas inlet: the DEM alone); parcels
// of 3 mm.
TEST(InputCases, AOneCellWideGridRunsEveryJobKind) {
  json scene = thinPrism();
  scene["apparatus"] = {{"type", "box"}, {"size", {0.01, 0.1, 0.02}}, {"outlet_top", true}};
  scene["effects"] = {"rolling_friction"};
  scene["grid"]["cell_size"] = {0.008, 0.005, 0.005};
  scene["particles"] = {{"diameter", 0.003}};
  scene["process"]["bed_mass"] = 0.002;
  scene["spray"]["spray_zone"]["apex"] = {0.0, 0.0, 0.01};
  scene["spray"]["nozzle_position"] = {0.0, 0.001, 0.01};
  scene["probes"] = json::parse(R"([{"name": "bed", "position": [0.0, 0.01, 0.01]}])");
  ASSERT_EQ(sceneGrid(scene).grid.shape[0], 1);
  runEveryKind("one-wide", scene);
}
