#include <gtest/gtest.h>

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

}  // namespace

// Each "default" of the schema equals the C++ initializer: a scene that gives only what is required
// loads into exactly the schema's defaults.
TEST(Defaults, SchemaDefaultsEqualCppDefaults) {
  const json& schema = SchemaValidator::get("scene").schema();
  std::map<std::string, json> defaults;
  collectDefaults(schema, schema, "", defaults);
  ASSERT_GT(defaults.size(), 60u);

  const json prismatic = {{"apparatus", {{"type", "prismatic_spouted_bed"}, {"draft_plates", json::object()}}},
                          {"grid", json::object()}, {"gas", json::object()}, {"particles", json::object()},
                          {"process", json::object()}, {"effects", json::array()}};
  json box = prismatic;
  box["apparatus"] = {{"type", "box"}};
  const json loaded[] = {sceneToJson(loadScene(prismatic)), sceneToJson(loadScene(box))};

  int compared = 0;
  for (const auto& [pointer, value] : defaults) {
    SCOPED_TRACE(pointer);
    bool found = false;
    for (const auto& doc : loaded) {
      const json::json_pointer p(pointer);
      if (!doc.contains(p)) continue;
      found = true;
      const json& actual = doc.at(p);
      if (pointer == "/grid/cell_size" && value.is_number()) {
        for (const auto& c : actual) EXPECT_TRUE(sameNumberOrValue(c, value)) << actual << " vs " << value;
      } else if (pointer == "/apparatus/type") {
        EXPECT_EQ(loaded[0].at(p), value);
      } else {
        EXPECT_TRUE(sameNumberOrValue(actual, value) ||
                    (actual.is_array() && value.is_array() && actual.size() == value.size() &&
                     std::equal(actual.begin(), actual.end(), value.begin(), sameNumberOrValue)))
            << "C++ " << actual << " vs schema " << value;
      }
      ++compared;
      break;
    }
    EXPECT_TRUE(found) << "schema default with no counterpart in the typed scene";
  }
  EXPECT_EQ(compared, static_cast<int>(defaults.size()));
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
