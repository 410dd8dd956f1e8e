#include "scene/SceneLoader.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/Errors.hpp"
#include "scene/SceneChecks.hpp"
#include "scene/SceneJson.hpp"
#include "scene/SchemaExplainer.hpp"
#include "scene/SchemaValidator.hpp"

namespace rcfd {
namespace {

using nlohmann::json;

std::string kindOf(const json& value) {
  switch (value.type()) {
    case json::value_t::array: return "an array";
    case json::value_t::string: return "a string";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::null: return "null";
    default: return value.is_number() ? "a number" : "a value";
  }
}

/// Text -> JSON; empty and malformed text become an InputError naming line and column.
json parseText(const std::string& text, const std::string& source, const char* what) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw InputError(source, "", std::string("empty document: expected a JSON object (") + what + ")");
  }
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    // nlohmann's text already says "parse error at line L, column C: ..."; drop its exception tag.
    std::string message = e.what();
    if (const auto tag = message.find("] "); message.rfind("[json.exception", 0) == 0 && tag != std::string::npos) {
      message = message.substr(tag + 2);
    }
    throw InputError(source, "", "malformed JSON: " + message);
  } catch (const json::exception& e) {
    // e.g. out_of_range 406: a number beyond the range of a double ("1e400").
    std::string message = e.what();
    if (const auto tag = message.find("] "); tag != std::string::npos) message = message.substr(tag + 2);
    throw InputError(source, "", "malformed JSON: " + message + (e.id == 406 ? " (beyond the range of a double)" : ""));
  }
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot read the file: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path, "", "error while reading the file");
  return text.str();
}

void requireObject(const json& document, const std::string& source, const char* what) {
  if (!document.is_object()) {
    throw InputError(source, "", std::string("expected a JSON object (") + what + "), got " + kindOf(document));
  }
}

std::vector<Violation> prefixed(std::vector<Violation> violations, const std::string& prefix) {
  for (auto& v : violations) v.pointer = prefix + v.pointer;
  return violations;
}

/// Converts and checks a scene that already passed the schema.
Scene convertScene(const json& document, std::vector<Violation>& violations) {
  Scene scene = sceneFromJson(document);
  auto semantic = checkSceneSemantics(scene, document);
  violations.insert(violations.end(), semantic.begin(), semantic.end());
  return scene;
}

}  // namespace

Scene loadScene(const json& document, const std::string& source) {
  requireObject(document, source, "a scene");
  auto violations = SchemaValidator::get("scene").validate(document);
  if (!violations.empty()) throw InputError(source, std::move(violations));
  Scene scene = convertScene(document, violations);
  if (!violations.empty()) throw InputError(source, std::move(violations));
  scene.source_json = document.dump(2);
  return scene;
}

Scene loadSceneText(const std::string& text, const std::string& source) {
  Scene scene = loadScene(parseText(text, source, "a scene"), source);
  scene.source_json = text;
  return scene;
}

Scene loadSceneFile(const std::string& path) { return loadSceneText(readFile(path), path); }

JobSpec loadJob(const json& document, const std::string& source, const std::string& baseDirectory) {
  requireObject(document, source, "a job");
  auto violations = SchemaValidator::get("job").validate(document);
  if (!violations.empty()) throw InputError(source, std::move(violations));

  JobSpec job;
  job.source = document;
  job.kind = document.at("kind").get<std::string>();
  job.database = document.value("database", std::string());
  job.duration = document.value("duration", job.duration);
  job.seed = document.value("seed", job.seed);
  job.checkpoint_interval = document.value("checkpoint_interval", job.checkpoint_interval);
  job.d0_values = document.value("d0_values", job.d0_values);
  job.discard = document.value("discard", job.discard);
  if (const auto e = document.find("ensemble"); e != document.end()) {  // K, or {"members": K}
    job.ensemble_members = e->is_object() ? e->at("members").get<int>() : e->get<int>();
  }

  // A /scene_patch (RFC 7396 merge patch) changes the scene for this job only; the patched scene is
  // validated as a whole, and its errors name the scene's pointers and where the scene came from.
  const json* patch = document.contains("scene_patch") ? &document["scene_patch"] : nullptr;
  if (document.contains("scene")) {
    const json& inline_scene = document["scene"];
    if (patch) {
      json patched = inline_scene;
      patched.merge_patch(*patch);
      try {
        job.scene = loadScene(patched, source);
      } catch (const InputError& e) {
        throw InputError(source + " (/scene with /scene_patch applied)", prefixed(e.violations(), "/scene"));
      }
    } else {
      job.scene = convertScene(inline_scene, violations);
      violations = prefixed(std::move(violations), "/scene");
      job.scene.source_json = inline_scene.dump(2);
    }
  } else {
    std::filesystem::path file = document["scene_file"].get<std::string>();
    if (file.is_relative()) file = std::filesystem::path(baseDirectory) / file;
    std::ifstream probe(file);
    if (!probe) {
      violations.push_back({"/scene_file", "cannot read scene file \"" + file.string() + "\": " + std::strerror(errno)});
    } else if (patch) {
      json patched = parseText(readFile(file.string()), file.string(), "a scene");
      requireObject(patched, file.string(), "a scene");
      patched.merge_patch(*patch);
      job.scene = loadScene(patched, file.string() + " with the /scene_patch of " + source);
    } else {
      job.scene = loadSceneFile(file.string());  // its own errors name the scene file and its pointers
    }
  }
  if (!violations.empty()) throw InputError(source, std::move(violations));
  violations = jobRuleViolations(job);
  if (!violations.empty()) throw InputError(source, std::move(violations));
  return job;
}

std::vector<Violation> jobRuleViolations(const JobSpec& job) {
  if (job.kind == "database") return prefixed(checkDatabaseScene(job.scene), "/scene");
  std::vector<Violation> out;
  if (job.kind != "calibration" && job.kind != "spray") return out;
  const double dt = job.scene.rcfd.dt;
  const std::int64_t steps = std::llround(job.duration / dt);
  if (!(steps >= 1)) {
    out.push_back({"/duration", std::to_string(job.duration) + " s is shorter than one time step /scene/rcfd/dt (" +
                                    std::to_string(dt) + " s)"});
  }
  if (job.kind != "calibration") return out;
  if (!(job.discard >= 0.0) || std::llround(job.discard / dt) >= steps) {
    out.push_back({"/discard", std::to_string(job.discard) + " s must be >= 0 and shorter than /duration (" +
                                   std::to_string(job.duration) + " s)"});
  }
  if (job.scene.probes.empty())
    out.push_back({"/scene/probes", "a calibration needs at least one probe for the penalty score"});
  std::set<double> seen;
  for (std::size_t i = 0; i < job.d0_values.size(); ++i) {
    const std::string pointer = "/d0_values/" + std::to_string(i);
    const double d0 = job.d0_values[i];
    if (!std::isfinite(d0) || d0 < 0.0) out.push_back({pointer, "D0 must be finite and >= 0 m2/s"});
    else if (!seen.insert(d0).second) out.push_back({pointer, "repeats an earlier D0 value"});
  }
  return out;
}

void requireJobRules(const JobSpec& job) {
  auto violations = jobRuleViolations(job);
  if (!violations.empty()) throw InputError("job", std::move(violations));
}

JobSpec loadJobFile(const std::string& path) {
  const json document = parseText(readFile(path), path, "a job");
  const auto parent = std::filesystem::path(path).parent_path();
  return loadJob(document, path, parent.empty() ? std::string(".") : parent.string());
}

const std::string& schemaText(const std::string& name) { return SchemaValidator::get(name).text(); }

const std::vector<std::string>& jobKinds() {
  static const std::vector<std::string> kinds =
      SchemaValidator::get("job").schema().at("properties").at("kind").at("enum").get<std::vector<std::string>>();
  return kinds;
}

}  // namespace rcfd
