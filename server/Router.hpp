#pragma once
/// \file Router.hpp
/// Maps a request to its handler (REST shape: docs/contracts.md, "HTTP API"), authenticates its caller
/// by the bearer token (everything but GET /v1/health and the web page's files needs one;
/// ServerConfig::users says whose it is) and answers health, schema, example, page and metrics requests
/// itself. Job and database handlers get the caller:
/// what is whose is decided there.

#include "DatabasesApi.hpp"
#include "HttpTypes.hpp"
#include "JobsApi.hpp"
#include "Metrics.hpp"
#include "Users.hpp"

namespace rcfd::server {

class Router {
 public:
  Router(JobStore& store, JobExecutor& pool, Metrics& metrics, const ServerConfig& config);

  /// Answers a complete request (JSON body already read and within its size limit) for `caller`, as
  /// authenticate() found it from the request's header (nullopt: no known token; 401 unless public).
  Response handle(const Request& req, const std::optional<Caller>& caller);
  /// The user whose token the header's "Authorization: Bearer <token>" carries; nullopt without one.
  std::optional<Caller> authenticate(const http::fields& headers) const;
  /// Whether the request needs no token.
  static bool isPublic(http::verb method, std::string_view target);
  /// Whether the request body is a database upload (streamed to a file, not held in memory).
  static bool isUpload(http::verb method, std::string_view target);

  /// 401 with the Bearer challenge; `instance` is the request path.
  StringResponse unauthorized(const std::string& instance) const;
  DatabasesApi& databases() { return databases_; }
  Metrics& metrics() { return metrics_; }
  const ServerConfig& config() const { return config_; }

 private:
  Response route(const Request& req, const Target& target, const std::optional<Caller>& caller);

  JobStore& store_;
  JobExecutor& pool_;
  Metrics& metrics_;
  const ServerConfig& config_;
  JobsApi jobs_;
  DatabasesApi databases_;
};

}  // namespace rcfd::server
