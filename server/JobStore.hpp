#pragma once
/// \file JobStore.hpp
/// The server's persistent state in SQLite (WAL, busy timeout): jobs with their state transitions and
/// progress, job summaries, coverage histogram bins and uploaded databases. The schema is versioned:
/// ordered migrations run once each, inside a transaction, when the store is opened.
/// Thread-safe: one connection guarded by a mutex (every statement is short).

#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace rcfd::server {

/// Job states (docs/contracts.md, "HTTP API"): final states are past tense.
namespace state {
inline constexpr const char* queued = "QUEUED";
inline constexpr const char* running = "RUNNING";
inline constexpr const char* succeeded = "SUCCEEDED";
inline constexpr const char* failed = "FAILED";
inline constexpr const char* cancelling = "CANCELLING";
inline constexpr const char* cancelled = "CANCELLED";
bool isValid(const std::string& s);
bool isFinal(const std::string& s);
}  // namespace state

/// One row of the jobs table.
struct JobRecord {
  std::int64_t seq = 0;          ///< insertion order (pagination key)
  std::string id;                ///< random 128-bit hex
  std::string kind;
  std::string state;
  std::string request;           ///< the submitted job document (canonical JSON)
  std::string idempotencyKey;
  std::string bodyHash;
  std::string databaseRef;       ///< a database job id or an uploaded database id; empty if none
  double progress = 0.0;         ///< fraction done [-]
  std::optional<double> simTime; ///< simulated time reached [s]
  std::optional<double> wallTime;///< solver wall time [s]
  std::optional<double> etaS;    ///< estimated seconds to completion [s]
  std::string createdAt, startedAt, finishedAt, updatedAt;  ///< RFC 3339 UTC, empty if not yet
  std::string error;
  int attempt = 0;               ///< number of times a worker started the job
  std::string owner;             ///< the user who submitted it (Users.hpp)
  std::string phase;             ///< the phase a running job is in ("fill", "run", ...); empty if none
  std::optional<double> phaseFraction;  ///< how far that phase is [-]
  std::string slurmJobId;        ///< the Slurm job of the current attempt (--executor slurm); empty if none
};

/// One bin of a job's coverage histogram.
struct CoverageBin {
  double lower = 0.0, upper = 0.0, count = 0.0;
};

/// An uploaded field database.
struct DatabaseRecord {
  std::string id, path, createdAt;
  std::int64_t bytes = 0;
  int frames = 0;
  std::string owner;  ///< the user who uploaded it
};

/// A state transition of a job (job_events).
struct JobEvent {
  std::string at, from, to, reason;
};

struct JobFilter {
  std::string state;  ///< empty: any
  std::string kind;   ///< empty: any
  std::string owner;  ///< empty: anyone's
  std::int64_t afterSeq = 0;
  int limit = 50;
};

class JobStore {
 public:
  /// Opens (creating if needed) DIR/rcfd.sqlite and applies pending migrations.
  explicit JobStore(const std::string& path);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  /// Schema version after migrations, and the number of migrations known to this build.
  int schemaVersion();
  static int latestSchemaVersion();

  /// Inserts a new QUEUED job owned by `job.owner`, its first event saying so. If `job.owner` already
  /// used `job.idempotencyKey`, nothing is inserted and that job is returned with `created == false`
  /// (the caller compares body hashes); keys are per owner.
  struct InsertResult {
    JobRecord job;
    bool created = false;
  };
  InsertResult insertJob(const JobRecord& job);

  std::optional<JobRecord> job(const std::string& id);
  std::vector<JobRecord> listJobs(const JobFilter& filter);
  std::vector<JobEvent> events(const std::string& id);

  /// Moves a job to `to` only if it is currently in `from` (compare and set); returns whether it did.
  bool transition(const std::string& id, const std::string& from, const std::string& to,
                  const std::string& reason = {}, const std::string& error = {});
  /// The oldest QUEUED jobs, in submission order.
  std::vector<JobRecord> queued(int limit);
  /// QUEUED -> RUNNING with attempt + 1 and started_at, the event saying `reason`, and no Slurm job
  /// yet (the previous attempt's is forgotten); false if it was no longer QUEUED.
  bool markStarted(const std::string& id, const std::string& reason = "worker started");
  /// Records the Slurm job that runs the job's current attempt (SlurmExecutor).
  void setSlurmJobId(const std::string& id, const std::string& slurmJobId);
  /// The solver's last progress line (docs/contracts.md, "Progress"); `phase` empty: none named.
  void updateProgress(const std::string& id, double fraction, std::optional<double> simTime,
                      std::optional<double> wallTime, std::optional<double> eta, const std::string& phase = {},
                      std::optional<double> phaseFraction = std::nullopt);
  /// RUNNING/CANCELLING -> SUCCEEDED, storing the summary and its coverage bins in one transaction.
  bool markSucceeded(const std::string& id, const nlohmann::json& summary,
                     const std::vector<CoverageBin>& bins);
  /// Jobs left RUNNING or CANCELLING by a server that stopped without finishing them.
  std::vector<JobRecord> unfinished();

  std::optional<nlohmann::json> summary(const std::string& id);
  std::vector<CoverageBin> coverage(const std::string& id);

  void insertDatabase(const DatabaseRecord& db);
  std::optional<DatabaseRecord> database(const std::string& id);
  /// The uploaded databases of `owner` (empty: everyone's), oldest first.
  std::vector<DatabaseRecord> listDatabases(const std::string& owner);

  /// Number of jobs in each state (every state present, zero if none).
  std::vector<std::pair<std::string, std::int64_t>> countByState();

  /// Called with a job's id after every committed change of its row (insert, transition, start,
  /// progress, success), under the store's lock: the listener must not call back into the store.
  /// The server is the only writer of the database, so this sees every change (JobViewCache).
  void setChangeListener(std::function<void(const std::string& id)> listener);

 private:
  void changed(const std::string& id);
  void migrate();
  void exec(const char* sql);
  JobRecord readJob(void* statement);

  std::mutex mutex_;
  sqlite3* db_ = nullptr;
  std::map<std::string, sqlite3_stmt*> statements_;  // prepared once, reused (under mutex_)
  std::function<void(const std::string&)> listener_;
};

/// Current UTC time as RFC 3339 with milliseconds, e.g. 2026-11-22T02:40:00.123Z.
std::string nowRfc3339();

}  // namespace rcfd::server
