#pragma once
/// \file SolverRun.hpp
/// What every executor does around one run of `rcfd-solve run job.json --out DIR --progress-json`,
/// wherever it runs (JobExecutor.hpp): write the job file into the job directory, store the solver's
/// progress lines, quote the end of its log in a failure, and store summary.json when it succeeds.

#include <filesystem>
#include <ios>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "JobStore.hpp"
#include "ServerConfig.hpp"

namespace rcfd::server {

/// Creates the job's directory and writes DIR/job.json: the submitted document, with a database
/// reference resolved to the database file's absolute path. Throws std::runtime_error if it cannot.
void writeJobFile(JobStore& store, const ServerConfig& config, const JobRecord& job);

/// True if the job may start now; false while its database job is still running, and false (the job
/// FAILED with the reason) when its database cannot be used.
bool databaseReady(JobStore& store, const ServerConfig& config, const JobRecord& job);

/// Stores the progress line `line` (docs/contracts.md, "Progress") as the job's progress.
void storeProgress(JobStore& store, const std::string& id, const nlohmann::json& line);

/// The last non-empty lines the solver wrote to its log from offset `from` on (this attempt's), for a
/// failure's reason.
std::string logTail(const std::filesystem::path& log, std::streamoff from);

/// Stores DIR/summary.json and its coverage bins as the job's result (RUNNING or CANCELLING ->
/// SUCCEEDED); when summary.json is missing or no JSON object the job FAILED instead, from `from`.
void storeSucceeded(JobStore& store, const ServerConfig& config, const std::string& id, const std::string& from);

/// "SIGKILL (9)".
std::string signalName(int sig);

}  // namespace rcfd::server
