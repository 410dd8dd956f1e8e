#include "DatabaseRef.hpp"

#include <algorithm>

#include "JobStore.hpp"
#include "ServerConfig.hpp"

namespace rcfd::server {

std::filesystem::path importCaseDirectory(const std::filesystem::path& importRoot, const std::string& caseDir) {
  namespace fs = std::filesystem;
  const fs::path given(caseDir);
  if (importRoot.empty() || given.empty() || given.is_absolute()) return {};
  std::error_code ec;
  const fs::path dir = fs::weakly_canonical(importRoot / given, ec);  // symbolic links and .. resolved
  if (ec || !fs::is_directory(dir, ec)) return {};
  const auto [rootEnd, dirAt] = std::mismatch(importRoot.begin(), importRoot.end(), dir.begin(), dir.end());
  if (rootEnd != importRoot.end()) return {};  // outside the root
  return dir;
}

DatabaseRef resolveDatabaseRef(JobStore& store, const ServerConfig& config, const std::string& ref,
                               const Caller* caller) {
  DatabaseRef out;
  const auto visible = [&](const std::string& owner) { return !caller || caller->mayAccess(owner); };
  if (auto job = store.job(ref); job && visible(job->owner)) {
    if (job->kind != "database" && job->kind != "import") {  // both write database.h5
      out.detail = "job " + ref + " is a " + job->kind + " job, not a database or import job";
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
