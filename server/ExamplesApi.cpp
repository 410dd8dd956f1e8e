#include "ExamplesApi.hpp"

#include <nlohmann/json.hpp>

#include "Problem.hpp"
#include "core/EmbeddedFiles.hpp"

namespace rcfd::server {

namespace {
constexpr std::string_view kDir = "examples/";
constexpr std::string_view kExtension = ".json";

/// The embedded examples by name: "examples/quick.json" is "quick" (files in subfolders are job files
/// naming a scene file, not scenes, and are not embedded).
std::map<std::string, std::string_view> examples() {
  std::map<std::string, std::string_view> out;
  for (const auto& [path, text] : embeddedFiles()) {
    const std::string_view p(path);
    if (p.size() <= kDir.size() + kExtension.size() || p.substr(0, kDir.size()) != kDir ||
        p.substr(p.size() - kExtension.size()) != kExtension)
      continue;
    const std::string_view name = p.substr(kDir.size(), p.size() - kDir.size() - kExtension.size());
    if (name.find('/') != std::string_view::npos) continue;
    out.emplace(std::string(name), text);
  }
  return out;
}
}  // namespace

StringResponse listExamples() {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [name, text] : examples()) {
    const auto scene = nlohmann::json::parse(text, nullptr, false);
    std::string description;
    if (scene.is_object() && scene.contains("description") && scene["description"].is_string())
      description = scene["description"].get<std::string>();
    list.push_back({{"name", name}, {"description", description}});
  }
  return jsonResponse(http::status::ok, {{"examples", std::move(list)}});
}

StringResponse getExample(const std::string& name, const Target& target) {
  const auto all = examples();
  const auto it = all.find(name);
  if (it == all.end()) {
    std::string names;
    for (const auto& [n, text] : all) names += (names.empty() ? "" : ", ") + n;
    return problem(http::status::not_found, "example-not-found", "Example not found",
                   "no example scene \"" + name + "\"; available: " + names, target.path);
  }
  return textResponse(http::status::ok, std::string(it->second), "application/json");
}

}  // namespace rcfd::server
