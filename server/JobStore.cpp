#include "JobStore.hpp"

#include <sqlite3.h>

#include <array>
#include <chrono>
#include <ctime>
#include <stdexcept>

namespace rcfd::server {

namespace state {
bool isValid(const std::string& s) {
  return s == queued || s == running || s == succeeded || s == failed || s == cancelling ||
         s == cancelled;
}
bool isFinal(const std::string& s) { return s == succeeded || s == failed || s == cancelled; }
}  // namespace state

std::string nowRfc3339() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buffer;
}

namespace {

// Ordered migrations: entry i brings the schema from version i to i + 1. Never edit a released
// entry; append a new one.
const std::array<const char*, 5> kMigrations = {
    R"sql(
CREATE TABLE jobs (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT NOT NULL UNIQUE,
  kind TEXT NOT NULL,
  state TEXT NOT NULL,
  request TEXT NOT NULL,
  idempotency_key TEXT UNIQUE,
  body_hash TEXT NOT NULL,
  database_ref TEXT,
  progress REAL NOT NULL DEFAULT 0,
  sim_time REAL,
  wall_time REAL,
  eta_s REAL,
  created_at TEXT NOT NULL,
  started_at TEXT,
  finished_at TEXT,
  updated_at TEXT NOT NULL,
  error TEXT,
  attempt INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX jobs_by_state ON jobs(state, seq);
CREATE INDEX jobs_by_kind ON jobs(kind, seq);
CREATE TABLE job_events (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  job_id TEXT NOT NULL REFERENCES jobs(id),
  at TEXT NOT NULL,
  from_state TEXT,
  to_state TEXT NOT NULL,
  reason TEXT
);
CREATE INDEX job_events_by_job ON job_events(job_id, id);
CREATE TABLE summaries (
  job_id TEXT PRIMARY KEY REFERENCES jobs(id),
  summary TEXT NOT NULL
);
CREATE TABLE coverage_bins (
  job_id TEXT NOT NULL REFERENCES jobs(id),
  bin INTEGER NOT NULL,
  lower REAL NOT NULL,
  upper REAL NOT NULL,
  count REAL NOT NULL,
  PRIMARY KEY (job_id, bin)
);
)sql",
    R"sql(
CREATE TABLE databases (
  id TEXT PRIMARY KEY,
  path TEXT NOT NULL,
  bytes INTEGER NOT NULL,
  frames INTEGER NOT NULL,
  created_at TEXT NOT NULL
);
)sql",
    // Users: jobs and uploads have an owner; what existed before belongs to the single token's user.
    // Idempotency keys become per owner (see scopedKey): the old ones are the admin's.
    R"sql(
ALTER TABLE jobs ADD COLUMN owner TEXT NOT NULL DEFAULT 'admin';
UPDATE jobs SET idempotency_key = 'admin/' || idempotency_key WHERE idempotency_key IS NOT NULL;
CREATE INDEX jobs_by_owner ON jobs(owner, seq);
ALTER TABLE databases ADD COLUMN owner TEXT NOT NULL DEFAULT 'admin';
)sql",
    // The phase a running job is in and how far that phase is (the solver's progress lines).
    R"sql(
ALTER TABLE jobs ADD COLUMN phase TEXT;
ALTER TABLE jobs ADD COLUMN phase_fraction REAL;
)sql",
    // The Slurm job running a job's current attempt (rcfd-server --executor slurm): a restarted server
    // follows it instead of submitting the job again.
    R"sql(
ALTER TABLE jobs ADD COLUMN slurm_job_id TEXT;
)sql"};

/// The stored form of an Idempotency-Key: OWNER/KEY. Keys are names clients choose ("quick-db-1"), so
/// two users may pick the same one, and one's key must neither replay nor reveal the other's job.
/// The column is UNIQUE since the first schema, and SQLite cannot drop that without rebuilding the
/// table, so the owner goes into the value (names never hold a "/").
std::string scopedKey(const std::string& owner, const std::string& key) {
  return key.empty() ? key : owner + "/" + key;
}
std::string unscopedKey(const std::string& stored) {
  const auto slash = stored.find('/');
  return slash == std::string::npos ? stored : stored.substr(slash + 1);
}

/// A prepared statement that finalizes itself.
class Statement {
 public:
  using Cache = std::map<std::string, sqlite3_stmt*>;
  /// With a cache, the statement is prepared once per connection and only reset after use.
  Statement(sqlite3* db, const std::string& sql, Cache* cache = nullptr) : db_(db), cached_(cache) {
    if (cache) {
      if (auto it = cache->find(sql); it != cache->end()) {
        stmt_ = it->second;
        return;
      }
    }
    if (sqlite3_prepare_v3(db, sql.c_str(), -1, cache ? SQLITE_PREPARE_PERSISTENT : 0, &stmt_,
                           nullptr) != SQLITE_OK)
      throw std::runtime_error(std::string("sqlite prepare: ") + sqlite3_errmsg(db));
    if (cache) cache->emplace(sql, stmt_);
  }
  ~Statement() {
    if (cached_) {
      sqlite3_reset(stmt_);
      sqlite3_clear_bindings(stmt_);
    } else {
      sqlite3_finalize(stmt_);
    }
  }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& v) {
    sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Statement& bindOrNull(int i, const std::string& v) {
    if (v.empty()) sqlite3_bind_null(stmt_, i);
    else bind(i, v);
    return *this;
  }
  Statement& bind(int i, double v) {
    sqlite3_bind_double(stmt_, i, v);
    return *this;
  }
  Statement& bind(int i, std::optional<double> v) {
    if (v) sqlite3_bind_double(stmt_, i, *v);
    else sqlite3_bind_null(stmt_, i);
    return *this;
  }
  Statement& bind(int i, std::int64_t v) {
    sqlite3_bind_int64(stmt_, i, v);
    return *this;
  }
  /// Steps once: true if a row is available.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw std::runtime_error(std::string("sqlite step: ") + sqlite3_errmsg(db_));
  }
  void run() { step(); }
  std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_, col);
    return p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
  }
  std::optional<double> optDouble(int col) const {
    if (sqlite3_column_type(stmt_, col) == SQLITE_NULL) return std::nullopt;
    return sqlite3_column_double(stmt_, col);
  }
  double real(int col) const { return sqlite3_column_double(stmt_, col); }
  std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }
  sqlite3_stmt* get() { return stmt_; }

 private:
  sqlite3* db_;
  Cache* cached_ = nullptr;
  sqlite3_stmt* stmt_ = nullptr;
};

/// BEGIN IMMEDIATE ... COMMIT, rolled back if not committed.
class Transaction {
 public:
  explicit Transaction(sqlite3* db) : db_(db) { execute("BEGIN IMMEDIATE"); }
  ~Transaction() {
    if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  void commit() {
    execute("COMMIT");
    done_ = true;
  }

 private:
  void execute(const char* sql) {
    char* message = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) != SQLITE_OK) {
      std::string text = message ? message : "unknown";
      sqlite3_free(message);
      throw std::runtime_error("sqlite: " + text);
    }
  }
  sqlite3* db_;
  bool done_ = false;
};

constexpr const char* kJobColumns =
    "seq, id, kind, state, request, idempotency_key, body_hash, database_ref, progress, sim_time, "
    "wall_time, eta_s, created_at, started_at, finished_at, updated_at, error, attempt, owner, phase, "
    "phase_fraction, slurm_job_id";

void insertEvent(sqlite3* db, const std::string& id, const std::string& from, const std::string& to,
                 const std::string& reason, const std::string& at) {
  Statement s(db,
              "INSERT INTO job_events(job_id, at, from_state, to_state, reason) "
              "VALUES(?1, ?2, ?3, ?4, ?5)");
  s.bind(1, id).bind(2, at).bindOrNull(3, from).bind(4, to).bindOrNull(5, reason).run();
}

}  // namespace

JobStore::JobStore(const std::string& path) {
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
      SQLITE_OK) {
    std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw std::runtime_error("cannot open job store " + path + ": " + message);
  }
  // Several server threads share the file; a writer waits up to 5 s instead of failing with BUSY.
  sqlite3_busy_timeout(db_, 5000);
  exec("PRAGMA journal_mode=WAL");
  exec("PRAGMA synchronous=NORMAL");
  exec("PRAGMA foreign_keys=ON");
  migrate();
}

JobStore::~JobStore() {
  for (auto& [sql, stmt] : statements_) sqlite3_finalize(stmt);
  sqlite3_close(db_);
}

void JobStore::exec(const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    std::string text = message ? message : "unknown";
    sqlite3_free(message);
    throw std::runtime_error(std::string("sqlite: ") + text + " in: " + sql);
  }
}

void JobStore::setChangeListener(std::function<void(const std::string& id)> listener) {
  std::lock_guard lock(mutex_);
  listener_ = std::move(listener);
}

void JobStore::changed(const std::string& id) {
  if (listener_) listener_(id);
}

int JobStore::latestSchemaVersion() { return static_cast<int>(kMigrations.size()); }

void JobStore::migrate() {
  std::lock_guard lock(mutex_);
  exec("CREATE TABLE IF NOT EXISTS schema_version (version INTEGER NOT NULL)");
  {
    Transaction tx(db_);
    Statement count(db_, "SELECT COUNT(*) FROM schema_version");
    count.step();
    if (count.integer(0) == 0) exec("INSERT INTO schema_version(version) VALUES(0)");
    tx.commit();
  }
  for (;;) {
    Transaction tx(db_);
    Statement current(db_, "SELECT version FROM schema_version");
    current.step();
    const auto version = current.integer(0);
    if (version > latestSchemaVersion())
      throw std::runtime_error("job store schema version " + std::to_string(version) +
                               " is newer than this server (" +
                               std::to_string(latestSchemaVersion()) + ")");
    if (version == latestSchemaVersion()) break;
    exec(kMigrations[static_cast<std::size_t>(version)]);
    Statement set(db_, "UPDATE schema_version SET version = ?1");
    set.bind(1, version + 1).run();
    tx.commit();
  }
}

int JobStore::schemaVersion() {
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT version FROM schema_version", &statements_);
  s.step();
  return static_cast<int>(s.integer(0));
}

JobRecord JobStore::readJob(void* statement) {
  auto& s = *static_cast<Statement*>(statement);
  JobRecord j;
  j.seq = s.integer(0);
  j.id = s.text(1);
  j.kind = s.text(2);
  j.state = s.text(3);
  j.request = s.text(4);
  j.idempotencyKey = unscopedKey(s.text(5));
  j.bodyHash = s.text(6);
  j.databaseRef = s.text(7);
  j.progress = s.real(8);
  j.simTime = s.optDouble(9);
  j.wallTime = s.optDouble(10);
  j.etaS = s.optDouble(11);
  j.createdAt = s.text(12);
  j.startedAt = s.text(13);
  j.finishedAt = s.text(14);
  j.updatedAt = s.text(15);
  j.error = s.text(16);
  j.attempt = static_cast<int>(s.integer(17));
  j.owner = s.text(18);
  j.phase = s.text(19);
  j.phaseFraction = s.optDouble(20);
  j.slurmJobId = s.text(21);
  return j;
}

JobStore::InsertResult JobStore::insertJob(const JobRecord& job) {
  std::lock_guard lock(mutex_);
  Transaction tx(db_);
  if (job.owner.empty()) throw std::logic_error("a job needs an owner");
  const std::string key = scopedKey(job.owner, job.idempotencyKey);
  if (!key.empty()) {
    Statement existing(db_, (std::string("SELECT ") + kJobColumns +
                             " FROM jobs WHERE idempotency_key = ?1").c_str());
    existing.bind(1, key);
    if (existing.step()) return {readJob(&existing), false};
  }
  const std::string now = nowRfc3339();
  Statement insert(db_,
                   "INSERT INTO jobs(id, kind, state, request, idempotency_key, body_hash, "
                   "database_ref, created_at, updated_at, owner) VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?8, ?9)");
  insert.bind(1, job.id).bind(2, job.kind).bind(3, std::string(state::queued)).bind(4, job.request);
  insert.bindOrNull(5, key).bind(6, job.bodyHash).bindOrNull(7, job.databaseRef);
  insert.bind(8, now).bind(9, job.owner).run();
  insertEvent(db_, job.id, {}, state::queued, "submitted by " + job.owner, now);
  Statement read(db_, std::string("SELECT ") + kJobColumns + " FROM jobs WHERE id = ?1", &statements_);
  read.bind(1, job.id).step();
  JobRecord created = readJob(&read);
  tx.commit();
  changed(job.id);
  return {created, true};
}

std::optional<JobRecord> JobStore::job(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement s(db_, std::string("SELECT ") + kJobColumns + " FROM jobs WHERE id = ?1", &statements_);
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  return readJob(&s);
}

std::vector<JobRecord> JobStore::listJobs(const JobFilter& filter) {
  std::lock_guard lock(mutex_);
  Statement s(db_, (std::string("SELECT ") + kJobColumns +
                    " FROM jobs WHERE seq > ?1 AND (?2 IS NULL OR state = ?2) AND "
                    "(?3 IS NULL OR kind = ?3) AND (?5 IS NULL OR owner = ?5) ORDER BY seq LIMIT ?4")
                       .c_str());
  s.bind(1, filter.afterSeq).bindOrNull(2, filter.state).bindOrNull(3, filter.kind);
  s.bind(4, static_cast<std::int64_t>(filter.limit)).bindOrNull(5, filter.owner);
  std::vector<JobRecord> out;
  while (s.step()) out.push_back(readJob(&s));
  return out;
}

std::vector<JobEvent> JobStore::events(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "SELECT at, from_state, to_state, reason FROM job_events WHERE job_id = ?1 ORDER BY id");
  s.bind(1, id);
  std::vector<JobEvent> out;
  while (s.step()) out.push_back({s.text(0), s.text(1), s.text(2), s.text(3)});
  return out;
}

bool JobStore::transition(const std::string& id, const std::string& from, const std::string& to,
                          const std::string& reason, const std::string& error) {
  std::lock_guard lock(mutex_);
  Transaction tx(db_);
  const std::string now = nowRfc3339();
  Statement s(db_,
              "UPDATE jobs SET state = ?3, updated_at = ?4, "
              "finished_at = CASE WHEN ?3 IN ('SUCCEEDED','FAILED','CANCELLED') THEN ?4 ELSE NULL END, "
              "error = CASE WHEN ?5 IS NULL THEN error ELSE ?5 END, "
              "eta_s = CASE WHEN ?3 = 'QUEUED' THEN NULL ELSE eta_s END, "
              "phase = CASE WHEN ?3 IN ('RUNNING','CANCELLING') THEN phase ELSE NULL END, "
              "phase_fraction = CASE WHEN ?3 IN ('RUNNING','CANCELLING') THEN phase_fraction ELSE NULL END "
              "WHERE id = ?1 AND state = ?2");
  s.bind(1, id).bind(2, from).bind(3, to).bind(4, now).bindOrNull(5, error).run();
  if (sqlite3_changes(db_) == 0) return false;
  insertEvent(db_, id, from, to, reason.empty() ? error : reason, now);
  tx.commit();
  changed(id);
  return true;
}

std::vector<JobRecord> JobStore::queued(int limit) {
  JobFilter f;
  f.state = state::queued;
  f.limit = limit;
  return listJobs(f);
}

bool JobStore::markStarted(const std::string& id, const std::string& reason) {
  std::lock_guard lock(mutex_);
  Transaction tx(db_);
  const std::string now = nowRfc3339();
  Statement s(db_,
              "UPDATE jobs SET state = 'RUNNING', attempt = attempt + 1, started_at = ?2, "
              "updated_at = ?2, error = NULL, slurm_job_id = NULL WHERE id = ?1 AND state = 'QUEUED'");
  s.bind(1, id).bind(2, now).run();
  if (sqlite3_changes(db_) == 0) return false;
  insertEvent(db_, id, state::queued, state::running, reason, now);
  tx.commit();
  changed(id);
  return true;
}

void JobStore::setSlurmJobId(const std::string& id, const std::string& slurmJobId) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "UPDATE jobs SET slurm_job_id = ?2, updated_at = ?3 WHERE id = ?1");
  s.bind(1, id).bindOrNull(2, slurmJobId).bind(3, nowRfc3339()).run();
  changed(id);
}

void JobStore::updateProgress(const std::string& id, double fraction, std::optional<double> simTime,
                              std::optional<double> wallTime, std::optional<double> eta, const std::string& phase,
                              std::optional<double> phaseFraction) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "UPDATE jobs SET progress = ?2, sim_time = ?3, wall_time = ?4, eta_s = ?5, "
              "updated_at = ?6, phase = ?7, phase_fraction = ?8 WHERE id = ?1");
  s.bind(1, id).bind(2, fraction).bind(3, simTime).bind(4, wallTime).bind(5, eta);
  s.bind(6, nowRfc3339()).bindOrNull(7, phase).bind(8, phaseFraction).run();
  changed(id);
}

bool JobStore::markSucceeded(const std::string& id, const nlohmann::json& summary,
                             const std::vector<CoverageBin>& bins) {
  std::lock_guard lock(mutex_);
  Transaction tx(db_);
  const std::string now = nowRfc3339();
  Statement current(db_, "SELECT state FROM jobs WHERE id = ?1");
  current.bind(1, id);
  if (!current.step()) return false;
  const std::string from = current.text(0);
  if (from != state::running && from != state::cancelling) return false;
  Statement s(db_,
              "UPDATE jobs SET state = 'SUCCEEDED', progress = 1, eta_s = 0, phase = NULL, phase_fraction = NULL, "
              "finished_at = ?2, updated_at = ?2 WHERE id = ?1");
  s.bind(1, id).bind(2, now).run();
  Statement sum(db_, "INSERT OR REPLACE INTO summaries(job_id, summary) VALUES(?1, ?2)");
  sum.bind(1, id).bind(2, summary.dump()).run();
  Statement clear(db_, "DELETE FROM coverage_bins WHERE job_id = ?1");
  clear.bind(1, id).run();
  Statement bin(db_,
                "INSERT INTO coverage_bins(job_id, bin, lower, upper, count) "
                "VALUES(?1, ?2, ?3, ?4, ?5)");
  for (std::size_t i = 0; i < bins.size(); ++i) {
    sqlite3_reset(bin.get());
    bin.bind(1, id).bind(2, static_cast<std::int64_t>(i)).bind(3, bins[i].lower);
    bin.bind(4, bins[i].upper).bind(5, bins[i].count).run();
  }
  insertEvent(db_, id, from, state::succeeded, "solver exited 0", now);
  tx.commit();
  changed(id);
  return true;
}

std::vector<JobRecord> JobStore::unfinished() {
  std::lock_guard lock(mutex_);
  Statement s(db_, (std::string("SELECT ") + kJobColumns +
                    " FROM jobs WHERE state IN ('RUNNING','CANCELLING') ORDER BY seq")
                       .c_str());
  std::vector<JobRecord> out;
  while (s.step()) out.push_back(readJob(&s));
  return out;
}

std::optional<nlohmann::json> JobStore::summary(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT summary FROM summaries WHERE job_id = ?1");
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  return nlohmann::json::parse(s.text(0));
}

std::vector<CoverageBin> JobStore::coverage(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT lower, upper, count FROM coverage_bins WHERE job_id = ?1 ORDER BY bin");
  s.bind(1, id);
  std::vector<CoverageBin> out;
  while (s.step()) out.push_back({s.real(0), s.real(1), s.real(2)});
  return out;
}

namespace {
/// A row of "SELECT id, path, bytes, frames, created_at, owner FROM databases".
DatabaseRecord databaseRow(const Statement& s) {
  DatabaseRecord d;
  d.id = s.text(0);
  d.path = s.text(1);
  d.bytes = s.integer(2);
  d.frames = static_cast<int>(s.integer(3));
  d.createdAt = s.text(4);
  d.owner = s.text(5);
  return d;
}
}  // namespace

void JobStore::insertDatabase(const DatabaseRecord& db) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "INSERT INTO databases(id, path, bytes, frames, created_at, owner) VALUES(?1, ?2, ?3, ?4, ?5, ?6)");
  if (db.owner.empty()) throw std::logic_error("a database needs an owner");
  s.bind(1, db.id).bind(2, db.path).bind(3, db.bytes).bind(4, static_cast<std::int64_t>(db.frames));
  s.bind(5, db.createdAt.empty() ? nowRfc3339() : db.createdAt).bind(6, db.owner).run();
}

std::optional<DatabaseRecord> JobStore::database(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT id, path, bytes, frames, created_at, owner FROM databases WHERE id = ?1");
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  return databaseRow(s);
}

std::vector<DatabaseRecord> JobStore::listDatabases(const std::string& owner) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "SELECT id, path, bytes, frames, created_at, owner FROM databases WHERE ?1 = '' OR owner = ?1 "
              "ORDER BY rowid");
  s.bind(1, owner);
  std::vector<DatabaseRecord> out;
  while (s.step()) out.push_back(databaseRow(s));
  return out;
}

std::vector<std::pair<std::string, std::int64_t>> JobStore::countByState() {
  std::vector<std::pair<std::string, std::int64_t>> out;
  for (const char* s : {state::queued, state::running, state::succeeded, state::failed,
                        state::cancelling, state::cancelled})
    out.emplace_back(s, 0);
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT state, COUNT(*) FROM jobs GROUP BY state", &statements_);
  while (s.step())
    for (auto& [name, n] : out)
      if (name == s.text(0)) n = s.integer(1);
  return out;
}

}  // namespace rcfd::server
