#pragma once
/// \file Router.hpp
/// Maps a request to its handler (REST shape in STYLE.md), checks the bearer token (everything but
/// GET /v1/health) and answers health, schema and metrics requests itself.

#include "DatabasesApi.hpp"
#include "HttpTypes.hpp"
#include "JobsApi.hpp"
#include "Metrics.hpp"

namespace rcfd::server {

class Router {
 public:
  Router(JobStore& store, WorkerPool& pool, Metrics& metrics, const ServerConfig& config);

  /// Answers a complete request (JSON body already read and within its size limit).
  Response handle(const Request& req);
  /// Whether the header carries "Authorization: Bearer <token>" with the configured token.
  bool authorized(const http::fields& headers) const;
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
  Response route(const Request& req, const Target& target);

  JobStore& store_;
  WorkerPool& pool_;
  Metrics& metrics_;
  const ServerConfig& config_;
  JobsApi jobs_;
  DatabasesApi databases_;
};

}  // namespace rcfd::server
