#include "scene/SchemaValidator.hpp"

#include <algorithm>
#include <map>
#include <mutex>
#include <stdexcept>
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>

#include "core/EmbeddedFiles.hpp"
#include "scene/SceneChecks.hpp"
#include "scene/SchemaExplainer.hpp"

namespace rcfd {
namespace {

std::string embeddedSchemaText(const std::string& name) {
  const std::string key = "schemas/" + name + ".schema.json";
  const auto& files = embeddedFiles();
  const auto it = files.find(key);
  if (it == files.end()) throw std::out_of_range("no embedded schema \"" + key + "\"");
  return std::string(it->second);
}

/// "scene.schema.json" or "https://.../scene.schema.json" -> "scene"; empty if not one of ours.
std::string schemaNameOf(const std::string& uri) {
  const std::string suffix = ".schema.json";
  std::string file = uri.substr(uri.rfind('/') == std::string::npos ? 0 : uri.rfind('/') + 1);
  if (const auto hash = file.find('#'); hash != std::string::npos) file.resize(hash);
  if (file.size() <= suffix.size() || file.compare(file.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return {};
  }
  return file.substr(0, file.size() - suffix.size());
}

/// valijson's context ("<root>", "[spray]", "[0]") as an RFC 6901 pointer.
std::string contextToPointer(const std::vector<std::string>& context) {
  std::string pointer;
  for (const auto& element : context) {
    if (element == "<root>") continue;
    std::string token = element;
    if (token.size() >= 2 && token.front() == '[' && token.back() == ']') token = token.substr(1, token.size() - 2);
    pointer = appendPointer(pointer, token);
  }
  return pointer;
}

bool isCompositeMessage(const std::string& text) {
  return text.rfind("Failed to validate against", 0) == 0 || text.rfind("Failed to validate item", 0) == 0;
}

}  // namespace

SchemaValidator::SchemaValidator(const std::string& name)
    : text_(embeddedSchemaText(name)), json_(nlohmann::json::parse(text_)), schema_(new valijson::Schema) {
  valijson::SchemaParser parser(valijson::SchemaParser::kDraft7);
  valijson::adapters::NlohmannJsonAdapter adapter(json_);
  auto fetch = [](const std::string& uri) -> const nlohmann::json* {
    const std::string other = schemaNameOf(uri);
    if (other.empty()) return nullptr;
    return new nlohmann::json(nlohmann::json::parse(embeddedSchemaText(other)));
  };
  auto release = [](const nlohmann::json* doc) { delete doc; };
  parser.populateSchema(adapter, *schema_, fetch, release);
}

SchemaValidator::~SchemaValidator() = default;

namespace {

void collectFilePaths(const nlohmann::json& root, const nlohmann::json& node, const std::string& pointer,
                      std::vector<std::string>& out, int depth) {
  if (!node.is_object() || depth > 64) return;
  if (node.value("x-file-path", false) && std::find(out.begin(), out.end(), pointer) == out.end()) out.push_back(pointer);
  if (const auto ref = node.find("$ref"); ref != node.end() && ref->is_string()) {
    const std::string target = ref->get<std::string>();
    if (target.rfind("#/", 0) == 0) collectFilePaths(root, root.at(nlohmann::json::json_pointer(target.substr(1))), pointer, out, depth + 1);
  }
  for (const char* branch : {"oneOf", "anyOf", "allOf"})
    if (const auto b = node.find(branch); b != node.end() && b->is_array())
      for (const auto& sub : *b) collectFilePaths(root, sub, pointer, out, depth + 1);
  if (const auto props = node.find("properties"); props != node.end() && props->is_object())
    for (const auto& [name, sub] : props->items()) collectFilePaths(root, sub, appendPointer(pointer, name), out, depth + 1);
}

}  // namespace

std::vector<std::string> SchemaValidator::filePathPointers() const {
  std::vector<std::string> out;
  collectFilePaths(json_, json_, "", out, 0);
  return out;
}

const SchemaValidator& SchemaValidator::get(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<SchemaValidator>> validators;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = validators[name];
  if (!slot) slot.reset(new SchemaValidator(name));
  return *slot;
}

bool SchemaValidator::conforms(const nlohmann::json& document, std::vector<Violation>* rawErrors) const {
  valijson::Validator validator(valijson::Validator::kStrongTypes);
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(document);
  const bool ok = validator.validate(*schema_, target, rawErrors ? &results : nullptr);
  if (rawErrors) {
    valijson::ValidationResults::Error error;
    while (results.popError(error)) rawErrors->push_back({contextToPointer(error.context), error.description});
  }
  return ok;
}

std::vector<Violation> SchemaValidator::validate(const nlohmann::json& document) const {
  if (auto limits = documentLimitViolations(document); !limits.empty()) return limits;
  std::vector<Violation> raw;
  if (conforms(document, &raw)) return {};

  // valijson says what is wrong; the explainer says it readably. Should the explainer ever miss a
  // rule valijson enforces, valijson's own leaf messages are reported rather than nothing.
  SchemaExplainer explainer(json_, [](const std::string& uri) -> const nlohmann::json* {
    const std::string other = schemaNameOf(uri);
    if (other.empty()) return nullptr;
    return &get(other).schema();
  });
  std::vector<Violation> readable = explainer.explain(document);
  if (!readable.empty()) return readable;
  for (const auto& v : raw) {
    if (!isCompositeMessage(v.message)) readable.push_back(v);
  }
  if (readable.empty()) readable = raw;
  return readable;
}

}  // namespace rcfd
