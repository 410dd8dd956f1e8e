#include <gtest/gtest.h>

#include <set>

#include "SceneTestUtil.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"
#include "scene/SchemaValidator.hpp"

using namespace rcfd;
using rcfd::test::readText;
using rcfd::test::sourcePath;

namespace {

struct BadScene {
  const char* file;     ///< in tests/data/bad_scenes/
  const char* pointer;  ///< the JSON pointer the message must name ("" for the whole document)
  const char* phrase;   ///< a piece of the message that states the rule
};

// One row per file in tests/data/bad_scenes/ (a test checks that none is left out).
const BadScene kBadScenes[] = {
    {"array_instead_of_object.json", "", "got an array"},
    {"box_keys_on_prismatic.json", "/apparatus/size", "unknown key \"size\" for type \"prismatic_spouted_bed\""},
    {"cell_size_too_big.json", "/grid/cell_size", "is larger than the apparatus extent"},
    {"cell_size_two_items.json", "/grid/cell_size", "(minItems)"},
    {"cone_angle_95.json", "/spray/cone_half_angle_deg", "95 is not < 90 (exclusiveMaximum)"},
    {"coupling_interval_zero.json", "/dem/coupling_interval", "0 is not >= 1 (minimum)"},
    {"deposition_model_unknown.json", "/spray/deposition_model", "\"sticky\" is not one of"},
    {"draft_plates_in_wall.json", "/apparatus/draft_plates/elevation", "cut into the wall"},
    {"duplicate_effect.json", "/effects/16", "duplicate \"drag\""},
    {"effects_not_array.json", "/effects", "expected an array"},
    {"empty.json", "", "empty document"},
    {"huge_number.json", "", "number overflow"},
    {"missing_grid.json", "/grid", "is missing (required)"},
    {"nan_string.json", "/gas/density", "expected a number, got a string \"NaN\" (type)"},
    {"negative_diameter.json", "/particles/diameter", "is not > 0 (exclusiveMinimum)"},
    {"negative_friction.json", "/dem/friction/particle_particle", "-0.1 is not >= 0 (minimum)"},
    {"not_json.json", "", "line 1, column 1"},
    {"nozzle_outside.json", "/spray/nozzle_position", "outside the apparatus's bounding box"},
    {"probe_missing_name.json", "/probes/0/name", "is missing (required)"},
    {"probe_outside.json", "/probes/3/position", "outside the apparatus's bounding box"},
    {"restitution_zero.json", "/dem/restitution/particle_wall", "0 is not > 0 (exclusiveMinimum)"},
    {"sequence_fractions_inverted.json", "/rcfd/path/min_sequence_fraction", "is not <= max_sequence_fraction"},
    {"spray_zone_inverted.json", "/spray/spray_zone/y_min", "0.1 is not < y_max = 0.02"},
    {"tracers_not_integer.json", "/rcfd/tracers", "expected an integer"},
    {"tracers_zero.json", "/rcfd/tracers", "0 is not >= 1 (minimum)"},
    {"truncated.json", "", "unexpected end of input"},
    {"unknown_apparatus_type.json", "/apparatus/type", "\"cylinder\" is not one of"},
    {"unknown_effect.json", "/effects/16", "unknown effect \"foo\"; valid effects are: gas, drag"},
    {"unknown_nested_key.json", "/rcfd/path/lenght", "unknown key \"lenght\""},
    {"unknown_top_key.json", "/colour", "unknown key \"colour\""},
    {"volume_fraction_one.json", "/rcfd/free_flight_alpha", "1 is not < 1 (exclusiveMaximum)"},
    {"wrong_type_width.json", "/apparatus/width", "expected a number, got a string"},
};

}  // namespace

TEST(BadScenes, EachNamesItsPointerAndRule) {
  for (const auto& bad : kBadScenes) {
    SCOPED_TRACE(bad.file);
    const std::string path = sourcePath(std::string("tests/data/bad_scenes/") + bad.file);
    try {
      loadSceneFile(path);
      ADD_FAILURE() << "loaded without error";
    } catch (const InputError& e) {
      ASSERT_EQ(e.violations().size(), 1u) << e.what();
      EXPECT_EQ(e.violations()[0].pointer, bad.pointer) << e.what();
      EXPECT_NE(e.violations()[0].message.find(bad.phrase), std::string::npos) << e.what();
      EXPECT_EQ(e.source(), path);
      // what() carries the pointer too: that is what the command line prints.
      if (*bad.pointer) {
        EXPECT_NE(std::string(e.what()).find(bad.pointer), std::string::npos);
      }
    }
  }
}

TEST(BadScenes, TableCoversEveryFile) {
  std::set<std::string> listed;
  for (const auto& bad : kBadScenes) listed.insert(bad.file);
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(sourcePath("tests/data/bad_scenes"))) {
    ++files;
    EXPECT_TRUE(listed.count(entry.path().filename().string())) << entry.path() << " has no row";
  }
  EXPECT_EQ(files, listed.size());
  EXPECT_GE(files, 20u);
}

TEST(BadScenes, ThreeErrorsAreAllReported) {
  auto doc = nlohmann::json::parse(readText(sourcePath("examples/quick.json")));
  doc["spray"]["cone_half_angle_deg"] = 95;
  doc["particles"]["diameter"] = "thick";
  doc["rcfd"]["bogus"] = 1;
  try {
    loadScene(doc, "three");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 3u) << e.what();
    std::set<std::string> pointers;
    for (const auto& v : e.violations()) pointers.insert(v.pointer);
    EXPECT_EQ(pointers, (std::set<std::string>{"/spray/cone_half_angle_deg", "/particles/diameter", "/rcfd/bogus"}));
  }
}

TEST(BadScenes, SemanticErrorsAreAllReported) {
  auto doc = nlohmann::json::parse(readText(sourcePath("examples/quick.json")));
  doc["spray"]["spray_zone"]["y_min"] = 0.2;
  doc["probes"][0]["position"] = {1.0, 0.0, 0.0};
  doc["probes"][1]["name"] = doc["probes"][2]["name"];
  try {
    loadScene(doc, "semantic");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    std::set<std::string> pointers;
    for (const auto& v : e.violations()) pointers.insert(v.pointer);
    EXPECT_EQ(pointers, (std::set<std::string>{"/spray/spray_zone/y_min", "/probes/0/position", "/probes/2/name"}))
        << e.what();
  }
}

// The explainer words the violations, valijson decides: on every bad scene that parses, both must
// agree that it breaks the schema or both that it does not.
TEST(BadScenes, ExplainerAgreesWithValijson) {
  const auto& validator = SchemaValidator::get("scene");
  int compared = 0;
  for (const auto& bad : kBadScenes) {
    const auto doc = nlohmann::json::parse(readText(sourcePath(std::string("tests/data/bad_scenes/") + bad.file)),
                                           nullptr, false);
    if (doc.is_discarded()) continue;
    std::vector<Violation> raw;
    const bool conforms = validator.conforms(doc, &raw);
    EXPECT_EQ(conforms, raw.empty()) << bad.file;
    if (!conforms) {
      EXPECT_FALSE(validator.validate(doc).empty()) << bad.file;
      ++compared;
      // valijson's context, as a JSON pointer, is the expected pointer or (for required and
      // additionalProperties, which valijson reports on the object) its parent.
      const std::string expected = bad.pointer;
      const std::string parent = expected.substr(0, expected.rfind('/'));
      bool located = false;
      for (const auto& v : raw) located = located || v.pointer == expected || v.pointer == parent;
      EXPECT_TRUE(located) << bad.file << ": no valijson error at " << expected;
    }
  }
  EXPECT_GE(compared, 15);
}

TEST(BadScenes, TextEdgeCasesAreInputErrors) {
  for (const std::string text : {"", "   \n", "null", "42", "\"scene\"", "{", "{\"apparatus\": NaN}", "[]", "{}"}) {
    SCOPED_TRACE(text);
    EXPECT_THROW(loadSceneText(text, "edge"), InputError);
  }
}

TEST(BadScenes, MissingFileIsAnInputError) {
  EXPECT_THROW(loadSceneFile(sourcePath("tests/data/no-such-scene.json")), InputError);
}

TEST(BadScenes, DocumentLimitsAreEnforcedBeforeTheSchema) {
  // 100,000 levels of nesting: refused with a pointer, without exhausting the stack.
  const std::string deep = "{\"apparatus\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
  try {
    loadSceneText(deep, "deep");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u) << e.what();
    EXPECT_NE(e.violations()[0].message.find("nested deeper"), std::string::npos);
    EXPECT_EQ(e.violations()[0].pointer.rfind("/apparatus/0/0/", 0), 0u);
  }
  // A long effects list would make uniqueItems quadratic.
  auto doc = nlohmann::json::parse(readText(sourcePath("examples/quick.json")));
  doc["effects"] = nlohmann::json::array();
  for (int i = 0; i < 100001; ++i) doc["effects"].push_back("gas");
  try {
    loadScene(doc, "long");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.violations().at(0).pointer, "/effects");
  }
  doc = nlohmann::json::parse(readText(sourcePath("examples/quick.json")));
  doc["rcfd"]["tracers"] = 18446744073709551615ull;  // valijson would read this as -1
  try {
    loadScene(doc, "big");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.violations().at(0).pointer, "/rcfd/tracers");
    EXPECT_NE(e.violations()[0].message.find("beyond the largest supported integer"), std::string::npos);
  }
}
