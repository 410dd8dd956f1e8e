#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "scene/SceneJson.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"
#include "scene/SchemaValidator.hpp"

using namespace rcfd;
using nlohmann::json;

namespace {

/// Every "default" in the scene schema, by the JSON pointer of its key in a scene document.
void collectDefaults(const json& schema, const json& root, const std::string& pointer,
                     std::map<std::string, json>& out, int depth = 0) {
  ASSERT_LT(depth, 20);
  const json* s = &schema;
  if (s->is_object() && s->contains("$ref")) {
    s = &root.at(json::json_pointer((*s)["$ref"].get<std::string>().substr(1)));
  }
  if (!s->is_object()) return;
  if (schema.is_object() && schema.contains("default")) out[pointer] = schema["default"];
  else if (s->contains("default")) out[pointer] = (*s)["default"];
  if (s->contains("properties")) {
    for (const auto& [key, sub] : (*s)["properties"].items()) {
      collectDefaults(sub, root, pointer + "/" + key, out, depth + 1);
    }
  }
  for (const char* branch : {"then", "else"}) {
    if (s->contains(branch)) collectDefaults((*s)[branch], root, pointer, out, depth + 1);
  }
  if (s->contains("allOf")) {
    for (const auto& sub : (*s)["allOf"]) collectDefaults(sub, root, pointer, out, depth + 1);
  }
}

bool sameNumberOrValue(const json& a, const json& b) {
  if (a.is_number() && b.is_number()) return a.get<double>() == b.get<double>();
  return a == b;
}

/// Pointers whose schema "default" differs from the C++ initializer (or has no typed counterpart):
/// a scene that gives only what is required loads into exactly the schema's defaults.
std::vector<std::string> defaultMismatches(const json& schema, std::size_t* compared) {
  std::map<std::string, json> defaults;
  collectDefaults(schema, schema, "", defaults);
  const json prismatic = {{"apparatus", {{"type", "prismatic_spouted_bed"}, {"draft_plates", json::object()}}},
                          {"grid", json::object()}, {"gas", json::object()}, {"particles", json::object()},
                          {"process", json::object()}, {"effects", json::array()}};
  json box = prismatic;
  box["apparatus"] = {{"type", "box"}};
  const json loaded[] = {sceneToJson(loadScene(prismatic)), sceneToJson(loadScene(box))};

  std::vector<std::string> mismatches;
  *compared = 0;
  for (const auto& [pointer, value] : defaults) {
    const json::json_pointer p(pointer);
    const json* actual = nullptr;
    for (const auto& doc : loaded) {
      if (doc.contains(p)) {
        actual = &doc.at(p);
        break;
      }
    }
    if (!actual) {
      mismatches.push_back(pointer + " (no counterpart in the typed scene)");
      continue;
    }
    ++*compared;
    bool same;
    if (pointer == "/grid/cell_size" && value.is_number()) {
      same = std::all_of(actual->begin(), actual->end(), [&](const json& c) { return sameNumberOrValue(c, value); });
    } else if (actual->is_array() && value.is_array()) {
      same = actual->size() == value.size() && std::equal(actual->begin(), actual->end(), value.begin(), sameNumberOrValue);
    } else {
      same = sameNumberOrValue(*actual, value);
    }
    if (!same) mismatches.push_back(pointer + ": C++ " + actual->dump() + ", schema " + value.dump());
  }
  return mismatches;
}

}  // namespace

TEST(Defaults, SchemaDefaultsEqualCppDefaults) {
  std::size_t compared = 0;
  const auto mismatches = defaultMismatches(SchemaValidator::get("scene").schema(), &compared);
  EXPECT_TRUE(mismatches.empty()) << ::testing::PrintToString(mismatches);
  EXPECT_GT(compared, 60u);
}

// The comparison itself can fail: a schema whose default drifted from the C++ value is caught.
TEST(Defaults, DriftedDefaultIsDetected) {
  json drifted = SchemaValidator::get("scene").schema();
  drifted["properties"]["particles"]["properties"]["diameter"]["default"] = 2.0e-3;
  drifted["definitions"]["draft_plates"]["properties"]["elevation"]["default"] = 0.01;
  std::size_t compared = 0;
  const auto mismatches = defaultMismatches(drifted, &compared);
  ASSERT_EQ(mismatches.size(), 2u) << ::testing::PrintToString(mismatches);
  EXPECT_EQ(mismatches[0].rfind("/apparatus/draft_plates/elevation", 0), 0u);
  EXPECT_EQ(mismatches[1].rfind("/particles/diameter", 0), 0u);
}

TEST(Defaults, MinimalSceneLoads) {
  const Scene s = loadSceneText(R"({"apparatus": {"type": "box", "size": [0.2, 0.3, 0.1]}, "grid": {"cell_size": [0.01, 0.02, 0.01]},
      "gas": {}, "particles": {}, "process": {}, "effects": ["transport"]})");
  EXPECT_EQ(s.apparatus.type, ApparatusSpec::Type::Box);
  EXPECT_TRUE(s.apparatus.size.isApprox(Vec3(0.2, 0.3, 0.1)));
  EXPECT_TRUE(s.grid.cell_size.isApprox(Vec3(0.01, 0.02, 0.01)));
  EXPECT_TRUE(s.hasEffect("transport"));
  EXPECT_FALSE(s.hasEffect("spray"));
  EXPECT_TRUE(s.probes.empty());
}
