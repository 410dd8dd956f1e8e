#include "Router.hpp"

#include "ExamplesApi.hpp"
#include "Ids.hpp"
#include "OpenApi.hpp"
#include "Problem.hpp"
#include "JobExecutor.hpp"
#include "WebPage.hpp"
#include "scene/SceneLoader.hpp"

namespace rcfd::server {

namespace {
constexpr const char* kVersion = RCFD_VERSION;

StringResponse methodNotAllowed(const Target& target, const std::string& allow) {
  auto res = problem(http::status::method_not_allowed, "method-not-allowed", "Method not allowed",
                     target.path + " supports " + allow, target.path);
  res.set(http::field::allow, allow);
  return res;
}

StringResponse noRoute(const Target& target) {
  return problem(http::status::not_found, "not-found", "Not found",
                 "no resource at " + target.path + " (the API lives under /v1; see docs/api.md)",
                 target.path);
}
}  // namespace

Router::Router(JobStore& store, JobExecutor& pool, Metrics& metrics, const ServerConfig& config)
    : store_(store),
      pool_(pool),
      metrics_(metrics),
      config_(config),
      jobs_(store, pool, config),
      databases_(store, config) {}

bool Router::isPublic(http::verb method, std::string_view target) {
  const auto path = target.substr(0, target.find('?'));
  // The web page's files hold no data (WebPage.hpp); everything the page shows comes from the API.
  return method == http::verb::get && (path == "/v1/health" || path == "/v1/health/" || isWebPath(path));
}

bool Router::isUpload(http::verb method, std::string_view target) {
  const auto path = target.substr(0, target.find('?'));
  return method == http::verb::post && (path == "/v1/databases" || path == "/v1/databases/");
}

std::optional<Caller> Router::authenticate(const http::fields& headers) const {
  const auto it = headers.find(http::field::authorization);
  if (it == headers.end()) return std::nullopt;
  const std::string_view value(it->value().data(), it->value().size());
  constexpr std::string_view scheme = "Bearer ";
  if (value.size() <= scheme.size() || !boost::beast::iequals(boost::beast::string_view(value.data(), scheme.size()),
                              boost::beast::string_view(scheme.data(), scheme.size())))
    return std::nullopt;
  return config_.users.authenticate(value.substr(scheme.size()));
}

StringResponse Router::unauthorized(const std::string& instance) const {
  auto res = problem(http::status::unauthorized, "unauthorized", "Unauthorized",
                     "send \"Authorization: Bearer <token>\" with the server's token "
                     "(rcfd --token or RCFD_TOKEN)",
                     instance);
  res.set(http::field::www_authenticate, "Bearer realm=\"rcfd\"");
  return res;
}

Response Router::handle(const Request& req, const std::optional<Caller>& caller) {
  const std::string raw(req.target());
  // The token comes first: a client without one learns nothing about its request but that.
  if (!isPublic(req.method(), raw) && !caller) return unauthorized(instancePath(raw));
  const auto target = parseTarget(raw);
  if (!target)
    return problem(http::status::bad_request, "invalid-target", "Malformed request target",
                   "the request target is not a valid path and query", instancePath(raw));
  if (target->dotSegment)
    return problem(http::status::bad_request, "invalid-target", "Path segments . and .. refused",
                   "resource names are never paths", target->path);
  try {
    return route(req, *target, caller);
  } catch (const std::exception& e) {
    return problem(http::status::internal_server_error, "internal", "Internal server error",
                   e.what(), target->path);
  }
}

Response Router::route(const Request& req, const Target& target, const std::optional<Caller>& caller) {
  const auto& s = target.segments;
  const auto method = req.method();
  const bool get = method == http::verb::get;
  const bool post = method == http::verb::post;

  if (s.size() == 1 && s[0] == "metrics") {
    if (!get) return methodNotAllowed(target, "GET");
    return textResponse(http::status::ok, metrics_.render(store_, pool_.busy(), pool_.slots()),
                        "text/plain; version=0.0.4; charset=utf-8");
  }
  if (isWebPath(target.path)) {
    if (!get) return methodNotAllowed(target, "GET");
    return webFile(target);
  }
  if (s.empty() || s[0] != "v1") return noRoute(target);

  if (s.size() == 2 && s[1] == "health") {
    if (!get) return methodNotAllowed(target, "GET");
    return jsonResponse(http::status::ok, {{"status", "ok"},
                                           {"version", kVersion},
                                           {"schema_version", store_.schemaVersion()},
                                           {"workers", pool_.slots()},
                                           {"workers_busy", pool_.busy()}});
  }
  // Only health and the page are public (handle() answered 401 for anything else without a caller).
  if (!caller) return unauthorized(target.path);
  const Caller& who = *caller;
  if (s.size() == 2 && s[1] == "openapi.json") {
    if (!get) return methodNotAllowed(target, "GET");
    static const std::string document = jsonText(openApiDocument(kVersion));
    return textResponse(http::status::ok, document, "application/json");
  }
  if (s.size() == 3 && s[1] == "schemas") {
    if (!get) return methodNotAllowed(target, "GET");
    try {
      return textResponse(http::status::ok, schemaText(s[2]), "application/schema+json");
    } catch (const std::out_of_range&) {
      return problem(http::status::not_found, "schema-not-found", "Schema not found",
                     "no schema \"" + s[2] + "\"; available: scene, job", target.path);
    }
  }
  if (s.size() >= 2 && s[1] == "examples") {
    if (s.size() > 3) return noRoute(target);
    if (!get) return methodNotAllowed(target, "GET");
    return s.size() == 2 ? listExamples() : getExample(s[2], target);
  }
  if (s.size() >= 2 && s[1] == "databases") {
    if (s.size() == 2) {
      if (get) return databases_.list(who);
      return methodNotAllowed(target, "GET, POST");  // uploads are routed by HttpSession (streamed bodies)
    }
    if (s.size() == 3) {
      if (!get) return methodNotAllowed(target, "GET");
      return databases_.get(s[2], target, who);
    }
    return noRoute(target);
  }
  if (s.size() >= 2 && s[1] == "jobs") {
    if (s.size() == 2) {
      if (post) return jobs_.submit(req, target, who);
      if (get) return jobs_.list(target, who);
      return methodNotAllowed(target, "GET, POST");
    }
    std::string id = s[2];
    // Custom method (AIP-136): POST /v1/jobs/{id}:cancel
    if (s.size() == 3 && id.size() > 7 && id.compare(id.size() - 7, 7, ":cancel") == 0) {
      if (!post) return methodNotAllowed(target, "POST");
      return jobs_.cancel(id.substr(0, id.size() - 7), target, who);
    }
    // POST /v1/jobs/{id}:retry
    if (s.size() == 3 && id.size() > 6 && id.compare(id.size() - 6, 6, ":retry") == 0) {
      if (!post) return methodNotAllowed(target, "POST");
      return jobs_.retry(id.substr(0, id.size() - 6), target, who);
    }
    if (s.size() == 3) {
      if (!get) return methodNotAllowed(target, "GET");
      return jobs_.get(id, target, who);
    }
    if (s.size() == 4 && !get) return methodNotAllowed(target, "GET");
    if (s.size() == 4 && s[3] == "result") return jobs_.result(id, target, who);
    if (s.size() == 4 && s[3] == "coverage") return jobs_.coverage(id, target, who);
    if (s.size() == 4 && s[3] == "events") return jobs_.events(id, target, who);
    if (s.size() == 5 && s[3] == "artifacts") {
      if (!get) return methodNotAllowed(target, "GET");
      return jobs_.artifact(id, s[4], target, who);
    }
    return noRoute(target);
  }
  return noRoute(target);
}

}  // namespace rcfd::server
