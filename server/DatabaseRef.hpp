#pragma once
/// \file DatabaseRef.hpp
/// What a job's "database" reference points at on the server: the database.h5 of a database or import job
/// (usable once that job SUCCEEDED, pending while it is QUEUED or RUNNING) or an uploaded database.

#include <filesystem>
#include <string>

#include "Users.hpp"

namespace rcfd::server {

class JobStore;
struct ServerConfig;

struct DatabaseRef {
  enum class Status { ready, pending, failed, unknown };
  Status status = Status::unknown;
  std::filesystem::path path;  ///< the HDF5 file (ready, pending)
  std::string detail;          ///< why it is failed or unknown, for messages
};

/// `caller`: whose job names the reference; a database job or upload this caller may not access is
/// unknown to it, exactly as a wrong id (nothing tells that it exists). nullptr: the server itself (the
/// worker starting a job accepted earlier), which sees all.
DatabaseRef resolveDatabaseRef(JobStore& store, const ServerConfig& config, const std::string& ref,
                               const Caller* caller = nullptr);

/// The directory an import job's `case_dir` names on the server: relative to `importRoot` and, with
/// symbolic links and ".." resolved, inside it and existing. Empty when it is not (or no root is set).
std::filesystem::path importCaseDirectory(const std::filesystem::path& importRoot, const std::string& caseDir);

}  // namespace rcfd::server
