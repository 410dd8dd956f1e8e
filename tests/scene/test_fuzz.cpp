// Random mutations of the example scenes: whatever the text, the loader returns a Scene or throws
// rcfd::InputError; no other exception, no crash.

#include <gtest/gtest.h>

#include <random>

#include "SceneTestUtil.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"
#include "scene/SceneChecks.hpp"
#include "scene/SchemaExplainer.hpp"
#include "scene/SchemaValidator.hpp"

using namespace rcfd;
using nlohmann::json;

namespace {

constexpr int kMutations = 5000;

/// Every leaf of a JSON document, by pointer.
void leaves(const json& value, const std::string& pointer, std::vector<std::string>& out) {
  if (value.is_object()) {
    for (const auto& [k, v] : value.items()) leaves(v, pointer + "/" + k, out);
  } else if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i) leaves(value[i], pointer + "/" + std::to_string(i), out);
  } else {
    out.push_back(pointer);
  }
}

std::string mutate(const std::string& text, std::mt19937_64& rng) {
  auto pick = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
  std::string t = text;
  switch (pick(9)) {
    case 0:  // flip a byte
      t[pick(t.size())] ^= static_cast<char>(1 << pick(8));
      break;
    case 1:  // delete a run
      t.erase(pick(t.size()), 1 + pick(20));
      break;
    case 2: {  // insert structural characters or garbage
      static const char* pieces[] = {"{", "}", "[", "]", ",", ":", "\"", "-", "1e999", "NaN", "\\u0000", "null", "\xff"};
      t.insert(pick(t.size()), pieces[pick(std::size(pieces))]);
      break;
    }
    case 3:  // truncate
      t.resize(pick(t.size()));
      break;
    default: try {  // structural mutations on the parsed document
      json doc = json::parse(text, nullptr, false);
      if (doc.is_discarded() || !doc.is_object() || doc.empty()) {  // already broken: break it more
        t.erase(pick(t.size() + 1), 1);
        break;
      }
      std::vector<std::string> paths;
      leaves(doc, "", paths);
      const json::json_pointer a(paths[pick(paths.size())]), b(paths[pick(paths.size())]);
      static const json replacements[] = {1e308, -1e308, 0, -1, 1, 0.5, 1e-300, "NaN", "", true, nullptr,
                                          json::array(), json::object(), 18446744073709551615ull,
                                          -9223372036854775807LL - 1, json::array({1, 2, 3})};
      bool compact = pick(2) == 0;
      switch (pick(5)) {
        case 0: {
          json va = doc[a], vb = doc[b];  // copies: one pointer may lie inside the other's value
          doc[a] = vb;
          doc[b] = va;
          break;
        }
        case 1: doc[a] = replacements[pick(std::size(replacements))]; break;
        case 2: {  // deep nesting
          json nested = doc[a];
          const std::size_t depth = 1 + pick(2000);
          for (std::size_t i = 0; i < depth; ++i) nested = json::array({std::move(nested)});
          doc[a] = std::move(nested);
          compact = true;  // indented, 2000 levels would be megabytes of blanks
          break;
        }
        case 3: doc.erase(doc.begin()); break;
        default: {  // an unknown key (or, in an array, an extra item)
          json& parent = doc[a.parent_pointer()];
          if (parent.is_object()) parent["x" + std::to_string(pick(100))] = 1;
          else if (parent.is_array()) parent.push_back(1);
          break;
        }
      }
      t = doc.dump(compact ? -1 : 2);
      if (pick(4) == 0) {  // a number too large for a double, as text
        const auto digit = t.find_first_of("123456789");
        if (digit != std::string::npos) t.insert(digit + 1, "e400");
      }
    } catch (const json::exception&) {  // the mutation itself did not apply: delete a byte instead
      t = text;
      t.erase(pick(t.size()), 1);
    }
  }
  return t;
}

}  // namespace

TEST(Fuzz, MutatedScenesGiveASceneOrAnInputError) {
  std::vector<std::string> texts;
  for (const auto& f : rcfd::test::exampleFiles()) texts.push_back(rcfd::test::readText(f));
  ASSERT_FALSE(texts.empty());
  std::mt19937_64 rng(20240611);
  int valid = 0, invalid = 0, agreements = 0;
  const auto& validator = SchemaValidator::get("scene");
  const SchemaExplainer explainer(validator.schema());
  for (int i = 0; i < kMutations; ++i) {
    const std::string& original = texts[i % texts.size()];
    std::string text = mutate(original, rng);
    if (i % 7 == 0) text = mutate(text, rng);  // some get two mutations
    // valijson decides, the explainer words: they must agree on every parsable mutation.
    const json parsed = json::parse(text, nullptr, false);
    if (!parsed.is_discarded() && documentLimitViolations(parsed).empty()) {
      try {
        std::vector<Violation> raw;
        const bool conforms = validator.conforms(parsed, &raw);
        const auto explained = explainer.explain(parsed);
        if (conforms != explained.empty()) {
          std::string detail;
          for (const auto& v : raw) detail += "\n  valijson " + v.pointer + ": " + v.message;
          for (const auto& v : explained) detail += "\n  explainer " + v.pointer + ": " + v.message;
          ADD_FAILURE() << "valijson and the explainer disagree" << detail;
        }
        ++agreements;
      } catch (const std::exception& e) {
        ADD_FAILURE() << "schema check threw " << e.what();
      }
    }
    try {
      if (i % 10 == 0) {
        // The same texts inside a job file.
        const json scene = json::parse(text, nullptr, false);
        if (scene.is_discarded()) {
          EXPECT_THROW(loadSceneText(text, "fuzz"), InputError);
          ++invalid;
          continue;
        }
        loadJob(json{{"kind", "spray"}, {"database", "db.h5"}, {"duration", 1.0}, {"scene", scene}}, "fuzz-job");
      } else {
        loadSceneText(text, "fuzz");
      }
      ++valid;
    } catch (const InputError& e) {
      ++invalid;
      EXPECT_FALSE(e.violations().empty());
    } catch (const std::exception& e) {
      ADD_FAILURE() << "mutation " << i << " threw " << typeid(e).name() << ": " << e.what() << "\n" << text.substr(0, 400);
    }
  }
  // Both outcomes occur: the mutations neither all break the scene nor all leave it intact.
  EXPECT_GT(valid, 50);
  EXPECT_GT(invalid, kMutations / 2);
  EXPECT_GT(agreements, kMutations / 3);
  std::cout << "fuzz: " << valid << " valid, " << invalid << " invalid of " << kMutations << "\n";
}
