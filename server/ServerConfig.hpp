#pragma once
/// \file ServerConfig.hpp
/// rcfd-server's settings, from its command line (main.cpp).

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "Users.hpp"

namespace rcfd::server {

/// How `--executor slurm` submits jobs (docs/cluster.md): the sbatch options a site chooses.
struct SlurmSettings {
  std::string partition;                       ///< --partition; empty: the cluster's default
  std::string account;                         ///< --account; empty: the user's default
  std::map<std::string, std::string> timeLimits;  ///< job kind -> --time (Slurm's formats); absent: the partition's
  int cpusPerJob = 1;                          ///< --cpus-per-task, and the solver's OMP_NUM_THREADS
  std::vector<std::string> extraArguments;     ///< further sbatch arguments, as given (--qos=..., --mem=...)
  std::filesystem::path solverPath;            ///< rcfd-solve as the compute nodes see it
  std::chrono::seconds pollInterval{5};        ///< between two squeue calls for all jobs
  int requeues = 2;                            ///< times a job Slurm ended by TIMEOUT, NODE_FAIL or PREEMPTED is submitted again
  std::chrono::seconds signalLead{60};         ///< SIGTERM this long before the time limit, to checkpoint
  int maxJobs = 1000;                          ///< jobs in Slurm at once; more stay QUEUED in the server
};

struct ServerConfig {
  std::filesystem::path dataDir;      ///< rcfd.sqlite, jobs/<id>/, databases/
  UserDirectory users;                ///< whose bearer tokens are accepted (everything but /v1/health)
  std::string pageTokenKey;           ///< signs page tokens (PageToken.hpp)
  std::filesystem::path tlsCertificate;  ///< PEM chain: the listener speaks HTTPS when set (with tlsKey)
  std::filesystem::path tlsKey;          ///< PEM private key of tlsCertificate
  int workers = 1;                    ///< concurrent solver processes (0: jobs stay QUEUED)
  int workerNice = 10;                ///< solvers run this much nicer than the server [0, 19]
  std::filesystem::path solverPath;   ///< the rcfd-solve executable
  /// OpenFOAM cases import jobs may read: their case_dir is relative to it and stays inside it. Empty:
  /// the server takes no import job (it reads no file a job names otherwise).
  std::filesystem::path importRoot;
  std::uint64_t jsonBodyLimit = 1u << 20;            ///< bytes of a JSON request body
  std::uint64_t uploadLimit = 8ull << 30;            ///< bytes of an uploaded database
  std::chrono::seconds readTimeout{30};              ///< header and JSON body read timeout
  std::chrono::seconds idleBeforeToken{5};           ///< header read timeout until a request carried a token
  int maxConnections = 1024;                         ///< open connections in total (at most the descriptor limit less 64)
  int maxConnectionsPerPeer = 512;                   ///< open connections from one address (a proxy counts as one)
  std::chrono::seconds uploadTimeout{3600};          ///< whole-upload timeout
  std::chrono::seconds uploadCheckTimeout{600};      ///< an upload's validation (a child process) is killed after this
  std::chrono::seconds shutdownGrace{120};           ///< wait for solvers to checkpoint on stop
  std::chrono::seconds cancelGrace{30};              ///< a cancelled solver still running after this is killed
  int autoRetries = 1;  ///< times a job whose solver was killed from outside (SIGKILL: out of memory) is requeued
  std::string executor = "local";  ///< where jobs run: "local" (child processes) or "slurm" (JobExecutor.hpp)
  SlurmSettings slurm;             ///< with executor "slurm"

  std::filesystem::path jobDir(const std::string& id) const { return dataDir / "jobs" / id; }
  std::filesystem::path databaseDir() const { return dataDir / "databases"; }
};

}  // namespace rcfd::server
