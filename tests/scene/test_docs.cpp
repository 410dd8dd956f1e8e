// docs/scene.md is checked against the schema: every key and every effect of the schema is
// documented, and the minimal scene it shows is valid.

#include <gtest/gtest.h>

#include <set>

#include "SceneTestUtil.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"
#include "scene/SchemaValidator.hpp"

using nlohmann::json;

namespace {
void collectKeys(const json& schema, std::set<std::string>& keys, int depth = 0) {
  if (depth > 30) return;
  if (schema.is_object()) {
    if (auto p = schema.find("properties"); p != schema.end() && p->is_object()) {
      for (const auto& [k, v] : p->items()) keys.insert(k);
    }
    for (const auto& [k, v] : schema.items()) collectKeys(v, keys, depth + 1);
  } else if (schema.is_array()) {
    for (const auto& v : schema) collectKeys(v, keys, depth + 1);
  }
}
}  // namespace

TEST(Docs, SceneDocumentationCoversTheSchema) {
  const std::string doc = rcfd::test::readText(rcfd::test::sourcePath("docs/scene.md"));
  ASSERT_FALSE(doc.empty());
  const json& schema = rcfd::SchemaValidator::get("scene").schema();
  std::set<std::string> keys;
  collectKeys(schema, keys);
  ASSERT_GT(keys.size(), 60u);
  for (const auto& key : keys) {
    EXPECT_NE(doc.find("`" + key + "`"), std::string::npos) << "docs/scene.md does not document `" << key << "`";
  }
  for (const auto& effect : schema["properties"]["effects"]["items"]["oneOf"]) {
    const std::string name = effect["const"].get<std::string>();
    EXPECT_NE(doc.find("| `" + name + "` |"), std::string::npos) << "effect " << name << " missing";
  }
}

TEST(Docs, MinimalSceneOfTheDocumentationIsValid) {
  const std::string doc = rcfd::test::readText(rcfd::test::sourcePath("docs/scene.md"));
  const auto start = doc.find("```json\n");
  ASSERT_NE(start, std::string::npos);
  const auto end = doc.find("```", start + 8);
  ASSERT_NE(end, std::string::npos);
  const rcfd::Scene scene = rcfd::loadSceneText(doc.substr(start + 8, end - start - 8), "docs/scene.md");
  EXPECT_TRUE(scene.hasEffect("transport"));
  EXPECT_DOUBLE_EQ(scene.apparatus.width, 0.25);
}
