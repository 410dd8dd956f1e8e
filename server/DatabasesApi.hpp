#pragma once
/// \file DatabasesApi.hpp
/// POST /v1/databases: a field database uploaded by a client (e.g. from another CFD code), streamed
/// to a temporary file by the HTTP session, validated with rcfd::FieldDatabase::open and only then
/// kept under DIR/databases/<id>.h5. GET /v1/databases/{id} describes one.

#include <filesystem>

#include "HttpTypes.hpp"
#include "JobStore.hpp"
#include "ServerConfig.hpp"
#include "Target.hpp"

namespace rcfd::server {

class DatabasesApi {
 public:
  DatabasesApi(JobStore& store, const ServerConfig& config) : store_(store), config_(config) {}

  /// Where the session streams an upload before validation (unique per call).
  std::filesystem::path temporaryUploadPath() const;
  /// Validates the uploaded file and registers it (201) or deletes it (422). Blocking: opens HDF5;
  /// call it off the io_context threads.
  StringResponse accept(const std::filesystem::path& file, const Target& target);
  Response get(const std::string& id, const Target& target);

 private:
  JobStore& store_;
  const ServerConfig& config_;
};

}  // namespace rcfd::server
