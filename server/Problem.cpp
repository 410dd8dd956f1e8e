#include "Problem.hpp"

#include "Target.hpp"
#include "scene/SchemaExplainer.hpp"

namespace rcfd::server {

StringResponse problem(http::status status, const std::string& type, const std::string& title,
                       const std::string& detail, const std::string& instance,
                       const nlohmann::json& errors) {
  nlohmann::json body = {{"type", "urn:rcfd:problem:" + type},
                         {"title", title},
                         {"status", static_cast<int>(status)},
                         {"detail", detail},
                         {"instance", instancePath(instance)}};
  if (!errors.is_null()) body["errors"] = errors;
  return textResponse(status, jsonText(body), "application/problem+json");
}

namespace {
/// The errors[] member: one {pointer, message} per violation.
nlohmann::json errorList(const std::vector<Violation>& violations) {
  nlohmann::json errors = nlohmann::json::array();
  for (const auto& v : violations) errors.push_back({{"pointer", v.pointer}, {"message", v.message}});
  return errors;
}
}  // namespace

StringResponse invalidInput(const InputError& error, const std::string& instance) {
  const auto count = error.violations().size();
  return problem(http::status::unprocessable_entity, "invalid-input", "Invalid input",
                 std::to_string(count) + (count == 1 ? " violation" : " violations") + " in " +
                     error.source() + "; see errors[] for each JSON pointer",
                 instance, errorList(error.violations()));
}

StringResponse invalidQueryParameter(const std::string& name, const std::string& message,
                                     const std::string& instance) {
  return problem(http::status::bad_request, "invalid-parameter", "Invalid query parameter",
                 "query parameter " + name + ": " + message, instance,
                 errorList({{appendPointer("/query", name), message}}));
}

// Invalid UTF-8 (a percent-decoded query value quoted in a message) becomes U+FFFD instead of an
// exception: the answer is still the 4xx it describes.
std::string jsonText(const nlohmann::json& body) {
  return body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

StringResponse jsonResponse(http::status status, const nlohmann::json& body) {
  return textResponse(status, jsonText(body), "application/json");
}

StringResponse textResponse(http::status status, std::string body, const std::string& contentType) {
  StringResponse res{status, 11};
  res.set(http::field::content_type, contentType);
  res.set(http::field::cache_control, "no-store");
  res.body() = std::move(body);
  res.prepare_payload();
  return res;
}

}  // namespace rcfd::server
