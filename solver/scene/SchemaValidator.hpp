#pragma once
/// \file SchemaValidator.hpp
/// The embedded JSON Schemas (schemas/<name>.schema.json), compiled once with valijson (draft 7).
/// valijson decides validity; SchemaExplainer words the violations (pointer, value, rule). The job
/// schema's `"$ref": "scene.schema.json"` is served from the embedded scene schema.

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/Errors.hpp"

namespace valijson {
class Schema;
}

namespace rcfd {

class SchemaValidator {
 public:
  /// The validator of schemas/<name>.schema.json ("scene", "job"); built on first use, thread-safe.
  /// Throws std::out_of_range for an unknown name.
  static const SchemaValidator& get(const std::string& name);

  /// Every violation of the schema; empty if the document conforms. Documents beyond the limits of
  /// documentLimitViolations() (SceneChecks.hpp) get those violations and are not validated further.
  std::vector<Violation> validate(const nlohmann::json& document) const;

  /// valijson's own verdict and its raw errors (pointer, valijson's text), for tests and fallback.
  bool conforms(const nlohmann::json& document, std::vector<Violation>* rawErrors = nullptr) const;

  const nlohmann::json& schema() const { return json_; }

  /// Pointers (into a document) of the string properties the schema marks "x-file-path": a file the
  /// solver opens by name. Follows "properties", local "$ref"s and oneOf/anyOf/allOf branches, not
  /// array items (no path lives in an array). A server refuses every one of them (the CLI opens them).
  std::vector<std::string> filePathPointers() const;
  const std::string& text() const { return text_; }

  ~SchemaValidator();
  SchemaValidator(const SchemaValidator&) = delete;
  SchemaValidator& operator=(const SchemaValidator&) = delete;

 private:
  explicit SchemaValidator(const std::string& name);

  std::string text_;
  nlohmann::json json_;
  std::unique_ptr<valijson::Schema> schema_;
};

}  // namespace rcfd
