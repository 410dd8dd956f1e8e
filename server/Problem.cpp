#include "Problem.hpp"

namespace rcfd::server {

StringResponse problem(http::status status, const std::string& type, const std::string& title,
                       const std::string& detail, const std::string& instance,
                       const nlohmann::json& errors) {
  nlohmann::json body = {{"type", "urn:rcfd:problem:" + type},
                         {"title", title},
                         {"status", static_cast<int>(status)},
                         {"detail", detail},
                         {"instance", instance}};
  if (!errors.is_null()) body["errors"] = errors;
  return textResponse(status, jsonText(body), "application/problem+json");
}

StringResponse invalidInput(const InputError& error, const std::string& instance) {
  nlohmann::json errors = nlohmann::json::array();
  for (const auto& v : error.violations())
    errors.push_back({{"pointer", v.pointer}, {"message", v.message}});
  const auto count = error.violations().size();
  return problem(http::status::unprocessable_entity, "invalid-input", "Invalid input",
                 std::to_string(count) + (count == 1 ? " violation" : " violations") + " in " +
                     error.source() + "; see errors[] for each JSON pointer",
                 instance, errors);
}

std::string jsonText(const nlohmann::json& body) { return body.dump() + "\n"; }

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
