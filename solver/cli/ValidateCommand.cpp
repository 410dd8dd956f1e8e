// rcfd-solve validate FILE.json: a scene or a job file (told apart by the job's "kind" key).
// Exit 0 with a one-line summary; exit 2 with every violation on stderr (main() prints InputError).

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"

namespace {

std::string describeScene(const rcfd::Scene& scene) {
  const auto& a = scene.apparatus;
  std::ostringstream s;
  s << (scene.name.empty() ? std::string("(unnamed)") : scene.name) << ": ";
  if (a.type == rcfd::ApparatusSpec::Type::Box) {
    s << "box " << a.size.x() << " x " << a.size.y() << " x " << a.size.z() << " m";
  } else {
    s << "prismatic spouted bed " << a.width << " x " << a.height << " x " << a.depth << " m"
      << (a.draft_plates ? " with draft plates" : "");
  }
  s << ", cells " << scene.grid.cell_size.x() << " m, " << scene.rcfd.tracers << " tracers, "
    << scene.effects.size() << " effects, " << scene.probes.size() << " probes";
  return s.str();
}

int validate(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw rcfd::InputError(path, "", "cannot read the file");
  std::ostringstream text;
  text << in.rdbuf();
  // A job file is an object with "kind"; anything else (including broken JSON) is checked as a scene,
  // whose loader reports parse errors with line and column.
  const auto document = nlohmann::json::parse(text.str(), nullptr, false);
  if (!document.is_discarded() && document.is_object() && document.contains("kind")) {
    const rcfd::JobSpec job = rcfd::loadJobFile(path);
    std::cout << "valid job: " << job.kind << " job on scene " << describeScene(job.scene) << "\n";
  } else {
    const rcfd::Scene scene = rcfd::loadSceneText(text.str(), path);
    std::cout << "valid scene: " << describeScene(scene) << "\n";
  }
  return rcfd::exit_code::success;
}

const bool registered = rcfd::cli::addCommand(
    "validate", "check a scene or job file against the schemas and the semantic rules",
    [](CLI::App& app) {
      auto file = std::make_shared<std::string>();
      app.add_option("FILE", *file, "scene or job file (JSON)")->required();
      return [file] { return validate(*file); };
    });

}  // namespace
