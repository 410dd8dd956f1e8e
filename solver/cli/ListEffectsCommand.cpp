// rcfd-solve list-effects: every effect name with its stage and one line of doc, read from the
// embedded scene schema (the single source of the effect vocabulary).

#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"

namespace {

int listEffects(bool asJson) {
  const auto schema = nlohmann::json::parse(rcfd::schemaText("scene"));
  const auto& options = schema.at("properties").at("effects").at("items").at("oneOf");
  std::size_t width = 0;
  for (const auto& o : options) width = std::max(width, o.at("const").get<std::string>().size());
  nlohmann::json list = nlohmann::json::array();
  for (const auto& o : options) {
    const std::string name = o.at("const").get<std::string>();
    const std::string stage = o.value("x-stage", std::string("?"));
    const std::string doc = o.value("description", std::string());
    if (asJson) {
      list.push_back({{"name", name}, {"stage", stage}, {"description", doc}});
    } else {
      std::cout << std::left << std::setw(static_cast<int>(width) + 2) << name << std::setw(9) << stage << doc
                << "\n";
    }
  }
  if (asJson) std::cout << list.dump(2) << "\n";
  return rcfd::exit_code::success;
}

const bool registered = rcfd::cli::addCommand(
    "list-effects", "every effect name with its stage and one line of doc", [](CLI::App& app) {
      auto json = std::make_shared<bool>(false);
      app.add_flag("--json", *json, "print a JSON array of {name, stage, description}");
      return [json] { return listEffects(*json); };
    });

}  // namespace
