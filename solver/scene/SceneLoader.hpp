#pragma once
/// \file SceneLoader.hpp
/// Scenes and job files from JSON: validated against the embedded schemas (schemas/*.schema.json,
/// valijson, draft 7), then checked for rules a schema cannot express (e.g. y_min < y_max), then turned
/// into typed structs. Every violation is reported, each with its JSON pointer, the value and the rule,
/// as one rcfd::InputError.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/Errors.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

/// A job file (schemas/job.schema.json); the scene is always resolved (scene_file read and validated).
struct JobSpec {
  std::string kind;           ///< one of jobKinds(): "database", "calibration" or "spray"
  Scene scene;
  std::string database;       ///< database path (CLI) or job id (server); empty for database jobs
  double duration = 0.0;      ///< simulated seconds (spray; calibration: per D0) [s]
  std::uint64_t seed = 1;
  double checkpoint_interval = 60.0;  ///< simulated seconds between checkpoints [s]
  std::vector<double> d0_values;      ///< calibration [m2/s]
  double discard = 5.0;               ///< calibration: ignored start [s]
  int ensemble_members = 1;           ///< spray: realisations K in [1, 64] (`ensemble`; 1: a plain run)
  nlohmann::json source;              ///< the job document as given
};

/// Parses, validates and converts a scene. `source` names the document in messages (a file path).
Scene loadScene(const nlohmann::json& document, const std::string& source = "scene");
Scene loadSceneFile(const std::string& path);
/// Parses text; malformed JSON, an empty file or a non-object is an InputError too.
Scene loadSceneText(const std::string& text, const std::string& source = "scene");

/// Job files: `scene_file` paths are resolved relative to `baseDirectory`.
JobSpec loadJob(const nlohmann::json& document, const std::string& source = "job",
                const std::string& baseDirectory = ".");
JobSpec loadJobFile(const std::string& path);

/// The rules a job must meet to start, beyond the schemas (pointers into the job document): for a
/// database job checkDatabaseScene; for calibration and spray jobs /duration at least one rcfd.dt;
/// for a calibration /discard in [0, /duration), at least one probe (/scene/probes) and D0 values
/// finite, >= 0 and distinct (/d0_values/i). loadJob refuses a job that breaks them, so the server does
/// at submit; the jobs check them again at start (requireJobRules) for specs built in code.
std::vector<Violation> jobRuleViolations(const JobSpec& job);
/// Throws InputError("job", the violations) if there are any.
void requireJobRules(const JobSpec& job);

/// The text of an embedded schema by name ("scene", "job"); throws std::out_of_range otherwise.
const std::string& schemaText(const std::string& name);

/// The job kinds, the job schema's `kind` enum in its order: what a job document may name and what the
/// server lists and filters by. The runners of `rcfd-solve run` are registered under the same names
/// (JobRunnerRegistry; the test Choices.JobKindsAreTheRegisteredRunners holds the two together).
const std::vector<std::string>& jobKinds();

}  // namespace rcfd
