#pragma once
/// \file SchemaExplainer.hpp
/// Readable violations of a JSON Schema (draft 7). valijson decides whether a document is valid (see
/// SchemaValidator), but its messages name neither the value nor the limit and its oneOf/if-then
/// reports repeat every branch. This walker knows where it is in the schema and says, per violation,
/// the JSON pointer, the offending value and the rule: `/spray/cone_half_angle_deg: 95 is not < 90
/// (exclusiveMaximum)`. It covers the keywords rcfd's schemas use: $ref, type, enum, const, minimum,
/// maximum, exclusiveMinimum, exclusiveMaximum, minLength, minItems, maxItems, uniqueItems, items,
/// properties, additionalProperties, required, if/then/else, allOf, oneOf, not and boolean schemas. A
/// schema may word its `not` violation itself with the extension keyword "x-message".

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/Errors.hpp"

namespace rcfd {

/// Appends one reference token to an RFC 6901 JSON pointer ("~" -> "~0", "/" -> "~1").
std::string appendPointer(const std::string& pointer, const std::string& token);

/// A value for a message: short JSON text, cut after `maxLength` characters.
std::string describeValue(const nlohmann::json& value, std::size_t maxLength = 60);

class SchemaExplainer {
 public:
  /// Resolves `$ref`s that are not local ("#/..."), e.g. "scene.schema.json"; returns nullptr if unknown.
  using ExternalResolver = std::function<const nlohmann::json*(const std::string& uri)>;

  explicit SchemaExplainer(const nlohmann::json& rootSchema, ExternalResolver external = nullptr);

  /// Every violation of `document`, in document order; empty if it conforms.
  std::vector<Violation> explain(const nlohmann::json& document) const;

 private:
  struct Context {
    const nlohmann::json* root;  ///< the schema document `#` refers to
  };
  void check(const nlohmann::json& schema, const Context& ctx, const nlohmann::json& value,
             const std::string& pointer, std::vector<Violation>& out, int depth) const;
  void checkObject(const nlohmann::json& schema, const Context& ctx, const nlohmann::json& value,
                   const std::string& pointer, std::vector<Violation>& out, int depth) const;
  void checkArray(const nlohmann::json& schema, const Context& ctx, const nlohmann::json& value,
                  const std::string& pointer, std::vector<Violation>& out, int depth) const;
  void checkOneOf(const nlohmann::json& schema, const Context& ctx, const nlohmann::json& value,
                  const std::string& pointer, std::vector<Violation>& out, int depth) const;
  bool matches(const nlohmann::json& schema, const Context& ctx, const nlohmann::json& value,
               int depth) const;
  /// Follows `$ref` (local or external); returns the target and the root its own refs refer to.
  const nlohmann::json& resolve(const nlohmann::json& schema, Context& ctx) const;
  std::string describeSchema(const nlohmann::json& schema, const Context& ctx) const;

  const nlohmann::json& root_;
  ExternalResolver external_;
};

}  // namespace rcfd
