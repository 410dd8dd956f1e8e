#include "OpenApi.hpp"

#include <regex>
#include <sstream>

#include "scene/SceneLoader.hpp"

namespace rcfd::server {

const std::vector<RouteSpec>& routeSpecs() {
  const char* const jsonType = "application/json";
  static const std::vector<RouteSpec> routes = {
      {"post", "/v1/jobs", "submitJob", "Submit a job (queued)", 202, jsonType, jsonType, "job"},
      {"get", "/v1/jobs", "listJobs", "List jobs, oldest first, a page at a time", 200, jsonType, nullptr, nullptr, true,
       "state,kind,owner,page_size,page_token"},
      {"get", "/v1/jobs/{id}", "getJob", "A job's state, progress and summary", 200, jsonType},
      {"get", "/v1/jobs/{id}/events", "listJobEvents", "A job's state transitions", 200, jsonType},
      {"post", "/v1/jobs/{id}:cancel", "cancelJob", "Cancel a queued or running job", 202, jsonType},
      {"post", "/v1/jobs/{id}:retry", "retryJob", "Run a failed or cancelled job again", 202, jsonType},
      {"get", "/v1/jobs/{id}/result", "getJobResult", "A finished job's summary.json", 200, jsonType},
      {"get", "/v1/jobs/{id}/coverage", "getJobCoverage", "A spray job's coverage (format jsonType, csv or h5)", 200, jsonType,
       nullptr, nullptr, true, "format,bins"},
      {"get", "/v1/jobs/{id}/artifacts/{name}", "getJobArtifact", "A file the job wrote", 200,
       "application/octet-stream"},
      {"post", "/v1/databases", "uploadDatabase", "Upload a field database (HDF5)", 201, jsonType, "application/x-hdf5"},
      {"get", "/v1/databases", "listDatabases", "The uploaded databases the caller may use, oldest first", 200,
       jsonType},
      {"get", "/v1/databases/{id}", "getDatabase", "An uploaded database's record", 200, jsonType},
      {"get", "/v1/examples", "listExamples", "The example scenes compiled into the server", 200, jsonType},
      {"get", "/v1/examples/{name}", "getExample", "An example scene", 200, jsonType},
      {"get", "/v1/schemas/{name}", "getSchema", "The JSON Schema of scenes (scene) or jobs (job)", 200,
       "application/schema+json"},
      {"get", "/v1/openapi.json", "getOpenApi", "This document", 200, jsonType},
      {"get", "/v1/health", "getHealth", "Liveness, version and workers (no token)", 200, jsonType, nullptr, nullptr,
       false},
      {"get", "/", "getWebPage", "The web page of the job service (no token; it asks the API with one)", 200,
       "text/html", nullptr, nullptr, false},
      {"get", "/web/{name}", "getWebFile", "A script, style sheet or image of the web page (no token)", 200,
       "text/javascript", nullptr, nullptr, false},
      {"get", "/metrics", "getMetrics", "Prometheus metrics", 200, "text/plain"},
  };
  return routes;
}

namespace {

using nlohmann::json;

/// The path parameters of a template: the names between braces.
std::vector<std::string> pathParameters(const std::string& path) {
  std::vector<std::string> names;
  static const std::regex brace("\\{([a-z_]+)\\}");
  for (auto it = std::sregex_iterator(path.begin(), path.end(), brace); it != std::sregex_iterator(); ++it)
    names.push_back((*it)[1]);
  return names;
}

/// An embedded JSON Schema as an OpenAPI 3.1 component (OpenAPI 3.1 schemas are JSON Schema 2020-12):
/// the draft-07 `definitions` of the file become `$defs`, and its references (to them and to the scene
/// schema's file) follow.
json component(const std::string& name) {
  std::string text = schemaText(name);
  static const std::regex definitions("#/definitions/");
  text = std::regex_replace(text, definitions, "#/components/schemas/" + name + "/$defs/");
  static const std::regex sceneFile("\"scene\\.schema\\.json\"");
  text = std::regex_replace(text, sceneFile, "\"#/components/schemas/scene\"");
  json schema = json::parse(text);
  if (schema.contains("definitions")) {
    schema["$defs"] = std::move(schema["definitions"]);
    schema.erase("definitions");
  }
  schema.erase("$schema");
  schema.erase("$id");
  return schema;
}

}  // namespace

json openApiDocument(const std::string& version) {
  json doc;
  doc["openapi"] = "3.1.0";
  doc["info"] = {{"title", "rcfd job service"},
                 {"version", version},
                 {"summary", "Recurrence CFD of spray coating in spouted beds: database, calibration and spray jobs"},
                 {"description", "Reference: docs/api.md. Errors are application/problem+json (RFC 9457)."}};
  doc["servers"] = json::array({{{"url", "/"}}});
  doc["security"] = json::array({{{"bearer", json::array()}}});
  json problemRef = {{"$ref", "#/components/schemas/problem"}};
  json paths = json::object();
  for (const RouteSpec& r : routeSpecs()) {
    json op = {{"operationId", r.operationId}, {"summary", r.summary}};
    const std::string path = r.path;
    json parameters = json::array();
    for (const std::string& p : pathParameters(path))
      parameters.push_back({{"name", p}, {"in", "path"}, {"required", true}, {"schema", {{"type", "string"}}}});
    std::stringstream query(r.query);
    for (std::string q; std::getline(query, q, ',');) {
      const bool count = q == "page_size" || q == "bins";
      parameters.push_back(
          {{"name", q}, {"in", "query"}, {"required", false}, {"schema", {{"type", count ? "integer" : "string"}}}});
    }
    if (!parameters.empty()) op["parameters"] = parameters;
    if (r.requestType) {
      const json schema = r.requestSchema ? json{{"$ref", std::string("#/components/schemas/") + r.requestSchema}}
                                          : json{{"type", "string"}, {"contentMediaType", r.requestType}};
      op["requestBody"] = {{"required", true}, {"content", {{r.requestType, {{"schema", schema}}}}}};
    }
    op["responses"] = {{std::to_string(r.status), {{"description", r.summary}, {"content", {{r.responseType, json::object()}}}}},
                       {"default", {{"description", "a problem (RFC 9457)"},
                                    {"content", {{"application/problem+json", {{"schema", problemRef}}}}}}}};
    if (!r.authenticated) op["security"] = json::array();
    paths[path][r.method] = std::move(op);
  }
  doc["paths"] = std::move(paths);
  doc["components"]["securitySchemes"]["bearer"] = {
      {"type", "http"}, {"scheme", "bearer"}, {"description", "the server's token (rcfd --token or RCFD_TOKEN)"}};
  doc["components"]["schemas"]["scene"] = component("scene");
  doc["components"]["schemas"]["job"] = component("job");
  json errorItem = {{"type", "object"},
                    {"properties", {{"pointer", {{"type", "string"}}}, {"message", {{"type", "string"}}}}}};
  json problem = {{"type", "object"}, {"required", {"type", "title", "status"}}};
  problem["properties"] = {{"type", {{"type", "string"}}},     {"title", {{"type", "string"}}},
                           {"status", {{"type", "integer"}}},  {"detail", {{"type", "string"}}},
                           {"instance", {{"type", "string"}}}, {"errors", {{"type", "array"}, {"items", errorItem}}}};
  doc["components"]["schemas"]["problem"] = std::move(problem);
  return doc;
}

}  // namespace rcfd::server
