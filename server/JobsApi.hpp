#pragma once
/// \file JobsApi.hpp
/// Handlers of /v1/jobs: submit (validated with rcfd::loadJob, Idempotency-Key), list (filters,
/// opaque page tokens), get (answered from JobViewCache while the row is unchanged), cancel, result,
/// coverage and artifacts. Each handler only reads or writes rows and files; solvers run in the
/// JobExecutor. Every handler acts for a Caller: a job is owned by its submitter, and a plain user's
/// request about another user's job is answered exactly as one about an id that does not exist (404),
/// so ids of other users' jobs are neither usable nor confirmed; admins act on every job.

#include "HttpTypes.hpp"
#include "JobStore.hpp"
#include "JobViewCache.hpp"
#include "ServerConfig.hpp"
#include "Target.hpp"
#include "Users.hpp"

namespace rcfd::server {

class JobExecutor;

class JobsApi {
 public:
  /// Registers the view cache as the store's change listener (until destruction).
  JobsApi(JobStore& store, JobExecutor& pool, const ServerConfig& config);
  ~JobsApi();
  JobsApi(const JobsApi&) = delete;
  JobsApi& operator=(const JobsApi&) = delete;

  /// The new job is owned by `caller`.
  Response submit(const Request& req, const Target& target, const Caller& caller);
  /// A plain user's own jobs only; an admin's: everyone's (or one user's, ?owner=NAME).
  Response list(const Target& target, const Caller& caller);
  Response get(const std::string& id, const Target& target, const Caller& caller);
  Response cancel(const std::string& id, const Target& target, const Caller& caller);
  /// A FAILED or CANCELLED job queued again; its solver resumes from the job's checkpoint if it has one.
  Response retry(const std::string& id, const Target& target, const Caller& caller);
  Response result(const std::string& id, const Target& target, const Caller& caller);
  Response events(const std::string& id, const Target& target, const Caller& caller);
  Response coverage(const std::string& id, const Target& target, const Caller& caller);
  Response artifact(const std::string& id, const std::string& name, const Target& target, const Caller& caller);

  /// The job as the API shows it (no request document unless `withRequest`).
  nlohmann::json toJson(const JobRecord& job, bool withRequest = false) const;

 private:
  /// Job `id` if `caller` may see it; another user's job is as absent as an unknown id.
  std::optional<JobRecord> visibleJob(const std::string& id, const Caller& caller);
  /// Artifact names the job directory holds now (fixed names and *.svg).
  std::vector<std::string> artifacts(const std::string& id) const;
  /// The job's job.json (open descriptor, taken over) as served: no path of this machine in it.
  Response servedJobFile(int fd, const JobRecord& job, const Target& target) const;

  JobStore& store_;
  JobExecutor& pool_;
  const ServerConfig& config_;
  JobViewCache views_;  // bodies of GET /v1/jobs/{id}
};

/// Whether `name` may be served from a job folder: a fixed list plus simple *.svg names.
bool isArtifactName(const std::string& name);

}  // namespace rcfd::server
