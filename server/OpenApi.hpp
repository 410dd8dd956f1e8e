#pragma once
/// \file OpenApi.hpp
/// The REST API as data: every route the Router answers (method, path template, what it does), and the
/// OpenAPI 3.1 document built from them and from the embedded JSON Schemas of scenes and jobs, served at
/// GET /v1/openapi.json. One source: a route added to the Router and not here fails the route test
/// (tests/server/test_openapi.cpp), and the request bodies are the schemas the server validates with.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace rcfd::server {

struct RouteSpec {
  const char* method;       ///< lower-case HTTP method, as OpenAPI spells it
  const char* path;         ///< template: {id}, {name}; a custom method as in /v1/jobs/{id}:cancel
  const char* operationId;  ///< camelCase
  const char* summary;
  int status;                ///< of a success: 200, 201 (stored) or 202 (accepted)
  const char* responseType;  ///< media type of the success
  const char* requestType = nullptr;    ///< media type of the request body, or none
  const char* requestSchema = nullptr;  ///< embedded schema of that body ("job"), or none
  bool authenticated = true;            ///< false: answered without the bearer token
  const char* query = "";               ///< the optional query parameters, comma-separated
};

/// Every route, in the order docs/api.md lists them.
const std::vector<RouteSpec>& routeSpecs();

/// The OpenAPI 3.1 document of the API of server version `version`.
nlohmann::json openApiDocument(const std::string& version);

}  // namespace rcfd::server
