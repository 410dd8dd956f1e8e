#pragma once
/// \file DatabasesApi.hpp
/// POST /v1/databases: a field database uploaded by a client (e.g. from another CFD code), streamed
/// to a temporary file by HttpSession, validated with rcfd::FieldDatabase::open in a child
/// process (HDF5 can crash or loop on a damaged file: only the child goes, killed after
/// --upload-check-timeout) and only then kept under DIR/databases/<id>.h5. GET /v1/databases/{id}
/// describes one to its uploader or an admin (to anyone else it does not exist: 404); GET /v1/databases
/// lists them to the same readers.

#include <filesystem>
#include <string_view>

#include "HttpTypes.hpp"
#include "JobStore.hpp"
#include "ServerConfig.hpp"
#include "Target.hpp"
#include "Users.hpp"

namespace rcfd::server {

/// The first argument that makes rcfd-server the child validating an upload (main.cpp).
inline constexpr std::string_view kCheckDatabaseArgument = "--check-uploaded-database";

/// The validating child's work: opens `file` as a field database and reads every frame, then prints
/// one JSON line, {"frames": N}, {"violations": [{"pointer", "message"}...]} or {"error": "..."}, to
/// stdout; returns the exit code (0: a report was printed).
int checkUploadedDatabase(const std::filesystem::path& file);

class DatabasesApi {
 public:
  DatabasesApi(JobStore& store, const ServerConfig& config) : store_(store), config_(config) {}

  /// Where the session streams an upload before validation (unique per call).
  std::filesystem::path temporaryUploadPath() const;
  /// Validates the uploaded file and registers it as `caller`'s (201) or deletes it (422). Blocking:
  /// waits for the validating child; call it off the io_context threads.
  StringResponse accept(const std::filesystem::path& file, const Target& target, const Caller& caller);
  Response get(const std::string& id, const Target& target, const Caller& caller);
  /// GET /v1/databases: the caller's uploads (an admin's: everyone's), oldest first.
  Response list(const Caller& caller);

 private:
  JobStore& store_;
  const ServerConfig& config_;
};

}  // namespace rcfd::server
