// Every choice by name has one list of names in the code (a registry or a NamedValue table) and the
// schemas offer exactly those names; a name the code does not know, in a scene or job built in code
// (no schema in between), is an InputError at the key's JSON pointer that lists the valid names.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "../gas/GasTestSupport.hpp"
#include "SceneTestUtil.hpp"
#include "cfddem/CfdDemSimulation.hpp"
#include "cfddem/coupling/DragModel.hpp"
#include "cfddem/gas/PressureSolver.hpp"
#include "jobs/JobRunner.hpp"
#include "recurrence/RecurrenceMatrix.hpp"
#include "recurrence/RecurrencePath.hpp"
#include "scene/SceneLoader.hpp"
#include "scene/SchemaValidator.hpp"
#include "spray/DepositionEfficiency.hpp"
#include "tracers/FluctuationModel.hpp"
#include "tracers/FrameInterpolation.hpp"
#include "tracers/TracerIntegrator.hpp"

namespace rcfd {
namespace {

using nlohmann::json;

std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

/// The schema's enum at `pointer` (into the schema document), sorted.
std::vector<std::string> schemaEnum(const std::string& schema, const std::string& pointer) {
  const json& s = SchemaValidator::get(schema).schema();
  return sorted(s.at(json::json_pointer(pointer)).at("enum").get<std::vector<std::string>>());
}

/// Runs `f`, which must throw an InputError with one violation at `pointer` whose message lists `names`.
template <class F>
void expectUnknownNameAt(F&& f, const std::string& pointer, const std::vector<std::string>& names) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << pointer;
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u) << e.what();
    EXPECT_EQ(e.violations()[0].pointer, pointer) << e.what();
    std::string list;
    for (const auto& n : sorted(names)) list += " " + n;
    EXPECT_NE(e.violations()[0].message.find("valid names are:" + list), std::string::npos) << e.what();
  }
}

TEST(Choices, SceneSchemaEnumsAreTheRegisteredNames) {
  const std::string p = "/properties/";
  EXPECT_EQ(schemaEnum("scene", p + "gas/properties/drag_model"), coupling::DragModelRegistry::names());
  EXPECT_EQ(schemaEnum("scene", p + "gas/properties/pressure_preconditioner"), gas::PreconditionerRegistry::names());
  EXPECT_EQ(schemaEnum("scene", p + "rcfd/properties/integrator"), namesOf(kTracerIntegrators));
  EXPECT_EQ(schemaEnum("scene", p + "rcfd/properties/frame_interpolation"), namesOf(kFrameInterpolations));
  EXPECT_EQ(schemaEnum("scene", p + "rcfd/properties/velocity_interpolation"), namesOf(kVelocityInterpolations));
  EXPECT_EQ(schemaEnum("scene", p + "rcfd/properties/fluctuation_model"), FluctuationModelRegistry::names());
  EXPECT_EQ(schemaEnum("scene", p + "rcfd/properties/path/properties/type"), PathGeneratorRegistry::names());
  EXPECT_EQ(schemaEnum("scene", p + "spray/properties/deposition_model"), DepositionModelRegistry::names());
}

TEST(Choices, JobKindsAreTheRegisteredRunners) {
  EXPECT_EQ(sorted(jobKinds()), JobRunnerRegistry::names());
  EXPECT_EQ(json(jobKinds()), SchemaValidator::get("job").schema().at(json::json_pointer("/properties/kind/enum")));
}

TEST(Choices, UnknownDragModelAndPreconditionerAreInputErrorsAtTheirKeys) {
  Scene s = test::boxScene(Vec3(0.04, 0.1, 0.04), Vec3(0.01, 0.01, 0.01), 0.0);
  s.effects = {"gas", "drag"};
  s.gas.drag_model = "stokes";
  expectUnknownNameAt([&] { CfdDemSimulation sim(s, 1); }, "/gas/drag_model", coupling::DragModelRegistry::names());
  s.gas.drag_model = "beetstra";
  s.gas.pressure_preconditioner = "amg";
  expectUnknownNameAt([&] { CfdDemSimulation sim(s, 1); }, "/gas/pressure_preconditioner",
                      gas::PreconditionerRegistry::names());
}

TEST(Choices, UnknownIntegratorAndNormAreInputErrorsNamingTheValidOnes) {
  Scene s;
  s.rcfd.integrator = "rk4";
  expectUnknownNameAt([&] { tracerIntegrator(s); }, "/rcfd/integrator", {"euler", "midpoint"});
  expectUnknownNameAt([] { parseRecurrenceNorm("l3"); }, "--norm", {"l1", "l2", "max"});
  expectUnknownNameAt([] { parseRecurrenceNorm("L2", "/recurrence/matrix@norm"); }, "/recurrence/matrix@norm",
                      {"l1", "l2", "max"});
  for (const auto& n : kRecurrenceNorms) {
    EXPECT_EQ(toString(parseRecurrenceNorm(n.name)), n.name);
  }
  for (const auto& i : kTracerIntegrators) {
    s.rcfd.integrator = i.name;
    EXPECT_EQ(tracerIntegrator(s), i.value);
  }
  s.rcfd.frame_interpolation = "cubic";
  expectUnknownNameAt([&] { frameInterpolation(s); }, "/rcfd/frame_interpolation", {"hold", "linear"});
  for (const auto& i : kFrameInterpolations) {
    s.rcfd.frame_interpolation = i.name;
    EXPECT_EQ(frameInterpolation(s), i.value);
  }
  s.rcfd.velocity_interpolation = "cubic";
  expectUnknownNameAt([&] { velocityInterpolation(s); }, "/rcfd/velocity_interpolation", {"mass_weighted", "trilinear"});
  for (const auto& i : kVelocityInterpolations) {
    s.rcfd.velocity_interpolation = i.name;
    EXPECT_EQ(velocityInterpolation(s), i.value);
  }
}

TEST(Choices, UnknownJobKindIsAnInputErrorAtKindAndMakesNoFolder) {
  JobSpec job;
  job.kind = "teleport";
  const auto dir = std::filesystem::temp_directory_path() / "rcfd-test-choices-no-folder";
  std::filesystem::remove_all(dir);
  RunOptions options;
  options.outDir = dir.string();
  expectUnknownNameAt([&] { runJob(job, options); }, "/kind", JobRunnerRegistry::names());
  EXPECT_FALSE(std::filesystem::exists(dir));
}

/// In a scene document the schema refuses the name first, at the same pointer, with the same names.
TEST(Choices, SchemaRefusesAnUnknownNameInASceneDocument) {
  const std::string scene = R"({"apparatus": {"type": "prismatic_spouted_bed"}, "grid": {}, "particles": {},
      "process": {}, "effects": [], "gas": {"drag_model": "stokes", "pressure_preconditioner": "amg"}})";
  try {
    loadSceneText(scene);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    std::vector<std::string> pointers;
    for (const auto& v : e.violations()) pointers.push_back(v.pointer);
    EXPECT_EQ(sorted(pointers), (std::vector<std::string>{"/gas/drag_model", "/gas/pressure_preconditioner"}))
        << e.what();
    EXPECT_NE(std::string(e.what()).find("\"gidaspow\""), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rcfd
