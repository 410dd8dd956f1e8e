#pragma once
/// \file JobsApi.hpp
/// Handlers of /v1/jobs: submit (validated with rcfd::loadJob, Idempotency-Key), list (filters,
/// opaque page tokens), get, cancel, result, coverage and artifacts. Each handler only reads or
/// writes rows and files; solvers run in the WorkerPool.

#include "HttpTypes.hpp"
#include "JobStore.hpp"
#include "ServerConfig.hpp"
#include "Target.hpp"

namespace rcfd::server {

class WorkerPool;

class JobsApi {
 public:
  JobsApi(JobStore& store, WorkerPool& pool, const ServerConfig& config)
      : store_(store), pool_(pool), config_(config) {}

  Response submit(const Request& req, const Target& target);
  Response list(const Target& target);
  Response get(const std::string& id, const Target& target);
  Response cancel(const std::string& id, const Target& target);
  Response result(const std::string& id, const Target& target);
  Response events(const std::string& id, const Target& target);
  Response coverage(const std::string& id, const Target& target);
  Response artifact(const std::string& id, const std::string& name, const Target& target);

  /// The job as the API shows it (no request document unless `withRequest`).
  nlohmann::json toJson(const JobRecord& job, bool withRequest = false) const;

 private:
  /// Artifact names the job directory holds now (fixed names and *.svg).
  std::vector<std::string> artifacts(const std::string& id) const;

  JobStore& store_;
  WorkerPool& pool_;
  const ServerConfig& config_;
};

/// Whether `name` may be served from a job folder: a fixed list plus simple *.svg names.
bool isArtifactName(const std::string& name);

}  // namespace rcfd::server
