// rcfd-solve list-effects: every effect name with its stage and one line of doc, then every model
// choice of the scene (the schema's enums: apparatus types, deposition and fluctuation models, path
// types), all read from the embedded scene schema, the single source of the vocabulary.

#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"

namespace {

using nlohmann::json;

/// Every "enum" of the schema, by the dotted scene key it constrains ("spray.deposition_model").
void collectChoices(const json& schema, const json& root, const std::string& key, json& out, int depth) {
  if (depth > 20 || !schema.is_object()) return;
  const json* s = &schema;
  if (s->contains("$ref")) {
    const std::string ref = (*s)["$ref"].get<std::string>();
    if (ref.rfind("#", 0) != 0) return;
    s = &root.at(json::json_pointer(ref.substr(1)));
  }
  if (s->contains("enum")) {
    out.push_back({{"key", key}, {"choices", (*s)["enum"]}, {"description", s->value("description", "")}});
  }
  if (s->contains("properties")) {
    for (const auto& [name, sub] : (*s)["properties"].items()) {
      if (name == "effects") continue;  // listed above, with stages
      collectChoices(sub, root, key.empty() ? name : key + "." + name, out, depth + 1);
    }
  }
  for (const char* branch : {"then", "else"}) {
    if (s->contains(branch)) collectChoices((*s)[branch], root, key, out, depth + 1);
  }
  if (s->contains("allOf")) {
    for (const auto& sub : (*s)["allOf"]) collectChoices(sub, root, key, out, depth + 1);
  }
}

int listEffects(bool asJson) {
  const auto schema = json::parse(rcfd::schemaText("scene"));
  const auto& options = schema.at("properties").at("effects").at("items").at("oneOf");
  json effects = json::array();
  for (const auto& o : options) {
    effects.push_back({{"name", o.at("const")}, {"stage", o.value("x-stage", "?")},
                       {"description", o.value("description", "")}});
  }
  json models = json::array();
  collectChoices(schema, schema, "", models, 0);
  if (asJson) {
    std::cout << json{{"effects", effects}, {"models", models}}.dump(2) << "\n";
    return rcfd::exit_code::success;
  }
  std::size_t width = 0;
  for (const auto& e : effects) width = std::max(width, e["name"].get<std::string>().size());
  std::cout << "effects (scene key \"effects\"):\n";
  for (const auto& e : effects) {
    std::cout << "  " << std::left << std::setw(static_cast<int>(width) + 2) << e["name"].get<std::string>()
              << std::setw(9) << e["stage"].get<std::string>() << e["description"].get<std::string>() << "\n";
  }
  std::cout << "\nmodels (scene key: choices):\n";
  for (const auto& m : models) {
    std::string choices;
    for (const auto& c : m["choices"]) choices += (choices.empty() ? "" : " | ") + c.get<std::string>();
    std::cout << "  " << m["key"].get<std::string>() << ": " << choices << "\n      "
              << m["description"].get<std::string>() << "\n";
  }
  return rcfd::exit_code::success;
}

const bool registered = rcfd::cli::addCommand(
    "list-effects", "every effect and model name with one line of doc", [](CLI::App& app) {
      auto asJson = std::make_shared<bool>(false);
      app.add_flag("--json", *asJson, "print {\"effects\": [{name, stage, description}], \"models\": [...]}");
      return [asJson] { return listEffects(*asJson); };
    });

}  // namespace
