#include "DatabaseRef.hpp"

#include "JobStore.hpp"
#include "ServerConfig.hpp"

namespace rcfd::server {

DatabaseRef resolveDatabaseRef(JobStore& store, const ServerConfig& config, const std::string& ref,
                               const Caller* caller) {
  DatabaseRef out;
  const auto visible = [&](const std::string& owner) { return !caller || caller->mayAccess(owner); };
  if (auto job = store.job(ref); job && visible(job->owner)) {
    if (job->kind != "database") {
      out.detail = "job " + ref + " is a " + job->kind + " job, not a database job";
      return out;
    }
    out.path = config.jobDir(ref) / "database.h5";
    if (job->state == state::succeeded) {
      out.status = DatabaseRef::Status::ready;
    } else if (job->state == state::queued || job->state == state::running) {
      out.status = DatabaseRef::Status::pending;
    } else {
      out.status = DatabaseRef::Status::failed;
      out.detail = "database job " + ref + " is " + job->state +
                   (job->error.empty() ? std::string() : ": " + job->error);
    }
    return out;
  }
  if (auto db = store.database(ref); db && visible(db->owner)) {
    out.status = DatabaseRef::Status::ready;
    out.path = db->path;
    return out;
  }
  out.detail = "\"" + ref + "\" is neither a database job id nor an uploaded database id";
  return out;
}

}  // namespace rcfd::server
