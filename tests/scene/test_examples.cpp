#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "SceneTestUtil.hpp"
#include "core/EmbeddedFiles.hpp"
#include "geometry/Apparatus.hpp"
#include "scene/SceneJson.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"

using namespace rcfd;
using rcfd::test::exampleFiles;
using rcfd::test::readText;

TEST(Examples, AllExampleScenesValidate) {
  const auto files = exampleFiles();
  ASSERT_GE(files.size(), 4u);
  for (const auto& file : files) {
    SCOPED_TRACE(file);
    try {
      const Scene scene = loadSceneFile(file);
      EXPECT_FALSE(scene.name.empty());
      EXPECT_EQ(scene.source_json, readText(file));
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

TEST(Examples, EmbeddedCopiesMatchTheFiles) {
  for (const auto& file : exampleFiles()) {
    const std::string key = "examples/" + std::filesystem::path(file).filename().string();
    const auto it = embeddedFiles().find(key);
    ASSERT_NE(it, embeddedFiles().end()) << key;
    EXPECT_EQ(std::string(it->second), readText(file)) << key;
  }
}

TEST(Examples, ProcellCarriesThePapersValues) {
  const Scene s = loadSceneFile(rcfd::test::sourcePath("examples/procell-unstabilised.json"));
  EXPECT_DOUBLE_EQ(s.apparatus.width, 0.25);
  EXPECT_DOUBLE_EQ(s.apparatus.depth, 0.2);
  EXPECT_DOUBLE_EQ(s.apparatus.prism_angle_deg, 60.0);
  EXPECT_NEAR(s.process.gas_flow_rate * 3600.0, 230.0, 1e-3);
  EXPECT_NEAR(s.spray.mass_rate * 3600.0, 0.3, 1e-4);
  EXPECT_DOUBLE_EQ(s.spray.cone_half_angle_deg, 17.0);
  EXPECT_EQ(s.rcfd.tracers, 472850);
  EXPECT_DOUBLE_EQ(s.rcfd.d0, 5e-4);
  EXPECT_DOUBLE_EQ(s.dem.sample_rate, 200.0);
  EXPECT_EQ(s.dem.coupling_interval, 25);
  EXPECT_FALSE(s.apparatus.draft_plates.has_value());
  // rho_P from 1.5 kg in 472,850 spheres of 1.8 mm: within 0.2 % of the scene's 1040 kg/m3.
  const double volume = 472850.0 * M_PI / 6.0 * std::pow(s.particles.diameter, 3);
  EXPECT_NEAR(s.process.bed_mass / volume, s.particles.density, 0.002 * s.particles.density);
  // The paper's spout probe of Fig. 7.
  const bool hasFig7Probe = std::any_of(s.probes.begin(), s.probes.end(), [](const ProbeSpec& p) {
    return p.position.isApprox(Vec3(0.0, 0.075, 0.05));
  });
  EXPECT_TRUE(hasFig7Probe);
  EXPECT_EQ(s.probes.size(), 10u);
  EXPECT_EQ(s.effects.size(), 16u);

  const Scene plates = loadSceneFile(rcfd::test::sourcePath("examples/procell-draft-plates.json"));
  ASSERT_TRUE(plates.apparatus.draft_plates.has_value());
  EXPECT_DOUBLE_EQ(plates.apparatus.draft_plates->height, 0.06);
  EXPECT_DOUBLE_EQ(plates.apparatus.draft_plates->gap, 0.045);
}

TEST(Examples, QuickIsTheProcellScaledWithDepth) {
  const Scene full = loadSceneFile(rcfd::test::sourcePath("examples/procell-unstabilised.json"));
  const Scene quick = loadSceneFile(rcfd::test::sourcePath("examples/quick.json"));
  const double ratio = quick.apparatus.depth / full.apparatus.depth;
  EXPECT_DOUBLE_EQ(quick.apparatus.depth, 0.02);
  EXPECT_NEAR(quick.process.gas_flow_rate, full.process.gas_flow_rate * ratio, 1e-9);
  EXPECT_NEAR(quick.process.bed_mass, full.process.bed_mass * ratio, 1e-12);
  EXPECT_NEAR(quick.spray.mass_rate, full.spray.mass_rate * ratio, 1e-12);
  // Superficial inlet velocity unchanged by the slice.
  EXPECT_NEAR(quick.process.gas_flow_rate / (quick.apparatus.inlet_width * quick.apparatus.depth),
              full.process.gas_flow_rate / (full.apparatus.inlet_width * full.apparatus.depth), 1e-6);
  EXPECT_DOUBLE_EQ(quick.spray.nozzle_position.z(), quick.apparatus.depth / 2);
  EXPECT_DOUBLE_EQ(quick.spray.spray_zone.apex.z(), quick.apparatus.depth / 2);
  for (const auto& p : quick.probes) EXPECT_DOUBLE_EQ(p.position.z(), quick.apparatus.depth / 2) << p.name;
}

TEST(Examples, JsonRoundTripReproducesTheScene) {
  for (const auto& file : exampleFiles()) {
    SCOPED_TRACE(file);
    const Scene a = loadSceneFile(file);
    const nlohmann::json written = sceneToJson(a);
    const Scene b = loadScene(written);  // the written form is itself a valid scene
    EXPECT_EQ(sceneToJson(b), written);
  }
}

// The aligned draft-plates slice puts each plate across a plane of cell faces, so no cell holds open
// volume on both sides of a plate (its particles' velocities would be averaged across it); the plain
// slice's plates lie inside a column of cells.
TEST(Examples, TheAlignedDraftPlatesSeparateTheCellsOnTheirTwoSides) {
  auto sidesShareACell = [](const std::string& example) {
    const Scene s = loadSceneFile(rcfd::test::sourcePath(example));
    const Apparatus apparatus(s.apparatus);
    const CartesianGrid grid = makeGrid(apparatus, s.grid);
    const auto& plates = *s.apparatus.draft_plates;
    const double inner = 0.5 * plates.gap, outer = inner + plates.thickness, y = plates.elevation + 0.5 * plates.height;
    bool shared = false;
    for (const double side : {-1.0, 1.0}) {
      const auto in = grid.flatIndexOf(Vec3(side * (inner - 1e-6), y, 0.01));
      const auto out = grid.flatIndexOf(Vec3(side * (outer + 1e-6), y, 0.01));
      shared = shared || in == out;
    }
    return shared;
  };
  EXPECT_FALSE(sidesShareACell("examples/quick-draft-plates-aligned.json"));
  EXPECT_TRUE(sidesShareACell("examples/quick-draft-plates.json"));
}
