#pragma once
/// \file Problem.hpp
/// Error responses as application/problem+json (RFC 9457): type, title, status, detail, instance and,
/// for invalid input, errors: [{pointer, message}] taken from rcfd::InputError::violations().

#include <nlohmann/json.hpp>
#include <string>

#include "HttpTypes.hpp"
#include "core/Errors.hpp"

namespace rcfd::server {

/// A problem response. `type` is a short slug ("invalid-json") turned into a URN; `instance` is the
/// path of the request the problem is about, sent as instancePath() makes it: never empty, ASCII.
StringResponse problem(http::status status, const std::string& type, const std::string& title,
                       const std::string& detail, const std::string& instance,
                       const nlohmann::json& errors = nullptr);

/// 422 listing every violation of an InputError with its JSON pointer.
StringResponse invalidInput(const InputError& error, const std::string& instance);

/// 400 for a query parameter the endpoint does not take as given, in the shape of invalidInput:
/// errors[] holds one entry whose pointer is "/query/NAME" (RFC 6901) and whose message says what is
/// allowed.
StringResponse invalidQueryParameter(const std::string& name, const std::string& message,
                                     const std::string& instance);

/// A JSON body with the given status (application/json).
StringResponse jsonResponse(http::status status, const nlohmann::json& body);
/// The body text jsonResponse sends: compact JSON (clients parse it; no indentation to write and
/// send) and a final newline for terminals.
std::string jsonText(const nlohmann::json& body);

/// A plain body with an explicit content type.
StringResponse textResponse(http::status status, std::string body, const std::string& contentType);

}  // namespace rcfd::server
