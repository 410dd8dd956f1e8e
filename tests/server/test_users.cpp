// Named users (--users-file) against a real rcfd-server on loopback: every job and upload is owned by
// its submitter; a plain user's request about another user's job or database is 404 like an unknown
// id (events, result, coverage, artifacts, cancel and retry included), listing and its page tokens
// show only the user's own jobs, an admin sees and acts on all; the users file is parsed strictly
// (the line of the first error named) and made with sha256sum as documented; and a store of the
// single-token server gains owners, its jobs the admin's. Workers are 0: jobs stay QUEUED.

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>

#include <cstdio>
#include <set>

#include "ServerFixture.hpp"
#include "SmallDatabase.hpp"

using namespace rcfd::test;
namespace http = boost::beast::http;

namespace {

/// What `printf %s TOKEN | sha256sum` prints ("HEX  -"), the way docs/deploy.md makes a users line.
std::string sha256sumOf(const std::string& token) {
  const std::string command = "printf %s '" + token + "' | sha256sum";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run sha256sum");
  std::string out;
  char chunk[256];
  while (const auto n = std::fread(chunk, 1, sizeof chunk, pipe)) out.append(chunk, n);
  if (::pclose(pipe) != 0 || out.size() < 64) throw std::runtime_error("sha256sum failed: " + out);
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

std::string hexOf(const std::string& token) { return sha256sumOf(token).substr(0, 64); }

void writeOwnerOnly(const std::filesystem::path& path, const std::string& text, mode_t mode = 0600) {
  std::ofstream(path) << text;
  ::chmod(path.c_str(), mode);
}

const std::map<std::string, std::string> kTokens = {
    {"alice", "alice-token-7f3a"}, {"bob", "bob-token-19c2"}, {"root", "root-token-e81d"}};

/// A users file as an operator writes it: a comment, a blank line, alice's line with the "-" that
/// sha256sum prints, bob's digest in capitals with a comment after it, an admin.
std::string usersFileText() {
  std::string bobHex = hexOf(kTokens.at("bob"));
  for (auto& c : bobHex) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return "# rcfd users: NAME ROLE SHA256HEX\n"
         "\n"
         "alice user " + sha256sumOf(kTokens.at("alice")) + "\n"
         "bob   user " + bobHex + "   # bob's laptop\n"
         "root admin " + hexOf(kTokens.at("root")) + "\n";
}

long long sqliteInt(const std::filesystem::path& db, const std::string& sql) {
  sqlite3* handle = nullptr;
  sqlite3_open_v2(db.c_str(), &handle, SQLITE_OPEN_READONLY, nullptr);
  sqlite3_stmt* stmt = nullptr;
  sqlite3_prepare_v2(handle, sql.c_str(), -1, &stmt, nullptr);
  long long value = -1;
  if (stmt && sqlite3_step(stmt) == SQLITE_ROW) value = sqlite3_column_int64(stmt, 0);
  sqlite3_finalize(stmt);
  sqlite3_close(handle);
  return value;
}

class Users : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = std::make_unique<TempDir>();
    writeOwnerOnly(usersFile(), usersFileText());
    start();
  }
  void start() {
    server_ = std::make_unique<ServerProcess>(
        data(), "", std::vector<std::string>{"--workers", "0", "--users-file", usersFile().string()});
  }
  std::filesystem::path data() const { return tmp_->path() / "data"; }
  std::filesystem::path usersFile() const { return tmp_->path() / "users"; }

  Reply as(const std::string& user, http::verb method, const std::string& target, const std::string& body = {},
           const std::map<std::string, std::string>& headers = {}) const {
    return httpRequest(server_->port(), method, target, kTokens.at(user), body, headers);
  }
  Reply get(const std::string& user, const std::string& target) const { return as(user, http::verb::get, target); }
  Reply post(const std::string& user, const std::string& target, const std::string& body = {}) const {
    return as(user, http::verb::post, target, body);
  }
  std::string submit(const std::string& user, const nlohmann::json& job) const {
    const auto r = post(user, "/v1/jobs", job.dump());
    EXPECT_EQ(r.status, 202) << r.body;
    EXPECT_EQ(r.json().at("owner"), user) << r.body;
    return r.json().at("id");
  }
  std::vector<std::string> reasons(const std::string& user, const std::string& id) const {
    std::vector<std::string> out;
    const auto events = get(user, "/v1/jobs/" + id + "/events").json();
    for (const auto& e : events.at("events")) out.push_back(e.at("reason"));
    return out;
  }
  /// Every job of the listing `query` as `user` sees it, page by page; `pages` counts them.
  std::vector<std::string> listAll(const std::string& user, const std::string& query, int& pages) const {
    std::vector<std::string> ids;
    std::string token;
    pages = 0;
    do {
      const auto r = get(user, "/v1/jobs?" + query + (token.empty() ? "" : "&page_token=" + token));
      EXPECT_EQ(r.status, 200) << r.body;
      if (r.status != 200 || ++pages > 50) break;
      const auto page = r.json();
      for (const auto& j : page.at("jobs")) ids.push_back(j.at("id"));
      token = page.value("next_page_token", "");
    } while (!token.empty());
    return ids;
  }
  static void expectNotFound(const Reply& r, const std::string& what) {
    EXPECT_EQ(r.status, 404) << what << ": " << r.body;
    EXPECT_EQ(r.header("content-type"), "application/problem+json") << what;
    EXPECT_EQ(r.body.find("alice"), std::string::npos) << what << ": the owner is not named: " << r.body;
  }

  std::unique_ptr<TempDir> tmp_;
  std::unique_ptr<ServerProcess> server_;
};

TEST_F(Users, AnotherUsersJobIsNotFoundWhileItsOwnerAndAnAdminActOnIt) {
  const std::string a = submit("alice", databaseJob(1));
  const std::string b = submit("bob", databaseJob(2));
  // A file in alice's job folder, as a solver would have written it: a downloadable artifact.
  std::filesystem::create_directories(data() / "jobs" / a);
  std::ofstream(data() / "jobs" / a / "solver.log") << "alice's solver\n";

  // Polled by alice twice (the second answer comes from the view cache), then asked for by bob: the
  // cached body is not his either.
  ASSERT_EQ(get("alice", "/v1/jobs/" + a).status, 200);
  ASSERT_EQ(get("alice", "/v1/jobs/" + a).json().at("owner"), "alice");
  const auto unknown = get("bob", "/v1/jobs/00000000000000000000000000000000");
  for (const std::string suffix : {"", "?view=full", "/events", "/result", "/coverage?format=csv",
                                   "/artifacts/solver.log", "/artifacts/job.json"}) {
    const auto r = get("bob", "/v1/jobs/" + a + suffix);
    expectNotFound(r, suffix);
    if (suffix.empty()) EXPECT_EQ(r.json().at("type"), unknown.json().at("type"));
  }
  expectNotFound(post("bob", "/v1/jobs/" + a + ":cancel"), "cancel");
  expectNotFound(post("bob", "/v1/jobs/" + a + ":retry"), "retry");
  EXPECT_EQ(get("alice", "/v1/jobs/" + a).json().at("state"), "QUEUED");  // bob's cancel did nothing
  EXPECT_EQ(reasons("alice", a), std::vector<std::string>{"submitted by alice"});

  // What the owner gets instead: the artifact, the conflict of a job without a result.
  const auto log = get("alice", "/v1/jobs/" + a + "/artifacts/solver.log");
  EXPECT_EQ(log.status, 200) << log.body;
  EXPECT_EQ(log.body, "alice's solver\n");
  EXPECT_EQ(get("alice", "/v1/jobs/" + a + "/result").status, 409);
  expectNotFound(get("alice", "/v1/jobs/" + b), "bob's job for alice");

  // An admin sees, downloads, cancels and retries anybody's job; the events say who acted.
  EXPECT_EQ(get("root", "/v1/jobs/" + a + "/artifacts/solver.log").body, "alice's solver\n");
  const auto seen = get("root", "/v1/jobs/" + b);
  ASSERT_EQ(seen.status, 200) << seen.body;
  EXPECT_EQ(seen.json().at("owner"), "bob");
  ASSERT_EQ(post("root", "/v1/jobs/" + b + ":cancel").status, 200);
  const auto retried = post("root", "/v1/jobs/" + b + ":retry");
  ASSERT_EQ(retried.status, 200) << retried.body;
  EXPECT_EQ(retried.json().at("owner"), "bob");  // acting on a job does not take it over
  ASSERT_EQ(post("bob", "/v1/jobs/" + b + ":cancel").status, 200);
  EXPECT_EQ(reasons("bob", b),
            (std::vector<std::string>{"submitted by bob", "cancelled by root",
                                      "retry requested by root; no checkpoint, starts from the beginning",
                                      "cancelled by bob"}));
  ASSERT_EQ(post("alice", "/v1/jobs/" + a + ":cancel").status, 200);
  EXPECT_EQ(reasons("root", a).back(), "cancelled by alice");
  // Metrics and health are as before: every user may read the metrics, nobody needs a token for health.
  EXPECT_EQ(get("bob", "/metrics").status, 200);
  EXPECT_EQ(httpRequest(server_->port(), http::verb::get, "/v1/health").status, 200);
  EXPECT_EQ(httpRequest(server_->port(), http::verb::get, "/v1/jobs", "not-a-users-token").status, 401);
}

TEST_F(Users, ListingShowsOnlyTheCallersJobsPageByPage) {
  std::vector<std::string> alices, bobs, all;
  for (int i = 0; i < 12; ++i) {
    const std::string user = i % 3 == 1 ? "bob" : "alice";  // 8 of alice's, 4 of bob's, interleaved
    const std::string id = submit(user, databaseJob(i));
    (user == "alice" ? alices : bobs).push_back(id);
    all.push_back(id);
  }
  int pages = 0;
  EXPECT_EQ(listAll("alice", "page_size=3", pages), alices);
  EXPECT_EQ(pages, 3);
  EXPECT_EQ(listAll("bob", "page_size=3", pages), bobs);
  EXPECT_EQ(pages, 2);
  const auto bobsPage = get("bob", "/v1/jobs").json();
  for (const auto& job : bobsPage.at("jobs")) EXPECT_EQ(job.at("owner"), "bob");
  // A page token is the listing's it was issued for: alice's is refused to bob, and to an admin.
  const std::string alicesToken = get("alice", "/v1/jobs?page_size=3").json().at("next_page_token");
  EXPECT_EQ(get("bob", "/v1/jobs?page_size=3&page_token=" + alicesToken).status, 400);
  EXPECT_EQ(get("root", "/v1/jobs?page_size=3&page_token=" + alicesToken).status, 400);
  EXPECT_EQ(get("alice", "/v1/jobs?page_size=3&page_token=" + alicesToken).status, 200);
  // A plain user cannot list another's jobs by asking; an admin lists all, or one user's.
  EXPECT_TRUE(get("alice", "/v1/jobs?owner=bob").json().at("jobs").empty());
  EXPECT_EQ(listAll("alice", "owner=alice&page_size=5", pages), alices);
  EXPECT_EQ(listAll("root", "page_size=5", pages), all);
  EXPECT_EQ(pages, 3);
  EXPECT_EQ(listAll("root", "owner=bob&page_size=3", pages), bobs);
  const std::string bobsForRoot = get("root", "/v1/jobs?owner=bob&page_size=3").json().at("next_page_token");
  EXPECT_EQ(get("root", "/v1/jobs?page_size=3&page_token=" + bobsForRoot).status, 400);  // other filter
  // Filters narrow the caller's own jobs.
  ASSERT_EQ(post("alice", "/v1/jobs/" + alices[2] + ":cancel").status, 200);
  EXPECT_EQ(listAll("alice", "state=CANCELLED", pages), std::vector<std::string>{alices[2]});
  EXPECT_TRUE(listAll("bob", "state=CANCELLED", pages).empty());
  EXPECT_EQ(listAll("root", "state=CANCELLED", pages), std::vector<std::string>{alices[2]});
}

TEST_F(Users, IdempotencyKeysArePerUser) {
  const std::map<std::string, std::string> key = {{"Idempotency-Key", "quick-db-1"}};
  const auto alice = as("alice", http::verb::post, "/v1/jobs", databaseJob(1).dump(), key);
  const auto bob = as("bob", http::verb::post, "/v1/jobs", databaseJob(1).dump(), key);
  ASSERT_EQ(alice.status, 202) << alice.body;
  ASSERT_EQ(bob.status, 202) << bob.body;
  EXPECT_NE(alice.json().at("id"), bob.json().at("id"));
  EXPECT_EQ(bob.header("idempotent-replayed"), "");  // a job of his own, not alice's replayed
  const auto replay = as("alice", http::verb::post, "/v1/jobs", databaseJob(1).dump(), key);
  EXPECT_EQ(replay.json().at("id"), alice.json().at("id"));
  EXPECT_EQ(replay.header("idempotent-replayed"), "true");
  const auto reused = as("bob", http::verb::post, "/v1/jobs", databaseJob(2).dump(), key);
  EXPECT_EQ(reused.status, 422);
  EXPECT_NE(reused.body.find(bob.json().at("id").get<std::string>()), std::string::npos) << reused.body;
  EXPECT_EQ(reused.body.find(alice.json().at("id").get<std::string>()), std::string::npos) << reused.body;
}

TEST_F(Users, ADatabaseIsItsUploadersAndOnlyTheyAndAdminsCanUseIt) {
  const auto file = tmp_->path() / "db.h5";
  writeSmallDatabase(quickScene(), file);
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const auto uploaded = as("alice", http::verb::post, "/v1/databases", bytes, {{"Content-Type", "application/x-hdf5"}});
  ASSERT_EQ(uploaded.status, 201) << uploaded.body;
  EXPECT_EQ(uploaded.json().at("owner"), "alice");
  const std::string db = uploaded.json().at("id");
  const std::string dbJob = submit("alice", databaseJob(3));

  expectNotFound(get("bob", "/v1/databases/" + db), "bob's look at alice's upload");
  EXPECT_EQ(get("root", "/v1/databases/" + db).json().at("owner"), "alice");
  // The listing of uploads follows the same rule: hers to her and to admins, nothing to bob.
  const auto listed = [&](const std::string& user) {
    std::vector<std::string> ids;
    const auto r = get(user, "/v1/databases");
    EXPECT_EQ(r.status, 200) << r.body;
    const nlohmann::json body = r.json();
    for (const auto& d : body.at("databases")) ids.push_back(d.at("id"));
    return ids;
  };
  EXPECT_EQ(listed("alice"), std::vector<std::string>{db});
  EXPECT_EQ(listed("root"), std::vector<std::string>{db});
  EXPECT_TRUE(listed("bob").empty());
  const auto spray = [&](const std::string& database) {
    return nlohmann::json{{"kind", "spray"}, {"scene", quickScene()}, {"database", database}, {"duration", 1.0}};
  };
  // To bob, alice's upload and database job are as unknown as a made-up id: same 422, same message.
  const auto madeUp = post("bob", "/v1/jobs", spray("0123456789abcdef0123456789abcdef").dump());
  for (const std::string& hers : {db, dbJob}) {
    const auto r = post("bob", "/v1/jobs", spray(hers).dump());
    EXPECT_EQ(r.status, 422) << r.body;
    EXPECT_EQ(r.json().at("errors").at(0).at("pointer"), "/database") << r.body;
    std::string expected = madeUp.json().at("errors").at(0).at("message");
    expected.replace(expected.find("0123456789abcdef0123456789abcdef"), 32, hers);
    EXPECT_EQ(r.json().at("errors").at(0).at("message"), expected);
  }
  EXPECT_EQ(post("alice", "/v1/jobs", spray(db).dump()).status, 202);
  EXPECT_EQ(post("alice", "/v1/jobs", spray(dbJob).dump()).status, 202);
  EXPECT_EQ(post("root", "/v1/jobs", spray(db).dump()).status, 202);
}

// --- the users file ---------------------------------------------------------------------------

/// The error of a server started with this users file (or "" if it started).
std::string refusal(const TempDir& tmp, const std::string& text, mode_t mode = 0600,
                    std::vector<std::string> extra = {}) {
  const auto file = tmp.path() / "users";
  writeOwnerOnly(file, text, mode);
  std::vector<std::string> args = {"--workers", "0", "--users-file", file.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  try {
    ServerProcess server(tmp.path() / "data", "", args);
    return {};
  } catch (const std::runtime_error& e) {
    return e.what();
  }
}

TEST(UsersFile, AMalformedFileStopsTheServerNamingTheLine) {
  TempDir tmp;
  const std::string a = hexOf("a-token"), b = hexOf("b-token");
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"alice user " + a + "\nbob root " + b + "\n", "line 2", "role \"root\" is not user or admin"},
      {"# users\n\nalice user 1234\n", "line 3", "not a SHA-256 digest"},
      {"alice user " + a + "\nalice admin " + b + "\n", "line 2", "appears twice"},
      {"alice user " + a + "\nbob user " + a + "\n", "line 2", "same token"},
      {"alice\n", "line 1", "expected 3 fields, found 1"},
      {"alice user " + a + " extra\n", "line 1", "expected 3 fields, found 4"},
      {"al/ice user " + a + "\n", "line 1", "user name \"al/ice\""},
      {"# only a comment\n\n", "no users", ""},
  };
  for (const auto& [text, line, what] : cases) {
    const std::string error = refusal(tmp, text);
    EXPECT_NE(error.find("rcfd-server: error: users file " + (tmp.path() / "users").string() + (line == "no users" ? ": " : " ") + line),
              std::string::npos)
        << text << "\n" << error;
    EXPECT_NE(error.find(what), std::string::npos) << text << "\n" << error;
  }
}

TEST(UsersFile, AFileOthersMayWriteIsRefusedOneTheyMayReadWarned) {
  TempDir tmp;
  const std::string line = "root admin " + hexOf("t") + "\n";
  const std::string writable = refusal(tmp, line, 0620);
  EXPECT_NE(writable.find("may be written by its group or others"), std::string::npos) << writable;
  EXPECT_NE(refusal(tmp, line, 0602).find("chmod 600"), std::string::npos);
  try {
    ServerProcess server(tmp.path() / "data", "", {"--workers", "0", "--users-file", (tmp.path() / "absent").string()});
    ADD_FAILURE() << "started without its users file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read users file"), std::string::npos) << e.what();
  }

  writeOwnerOnly(tmp.path() / "users", line, 0644);
  ServerProcess server(tmp.path() / "data", "", {"--workers", "0", "--users-file", (tmp.path() / "users").string()});
  EXPECT_NE(server.stderrText().find("warning: users file " + (tmp.path() / "users").string() + " is readable"),
            std::string::npos)
      << server.stderrText();
  EXPECT_EQ(httpRequest(server.port(), http::verb::get, "/v1/jobs", "t").status, 200);
}

TEST(UsersFile, IsNotCombinedWithATokenFile) {
  TempDir tmp;
  const std::string error = refusal(tmp, "root admin " + hexOf("t") + "\n", 0600, {"--token-file", "/dev/null"});
  EXPECT_NE(error.find("excludes"), std::string::npos) << error;
}

// --- a store of the single-token server -------------------------------------------------------

TEST(UsersStore, AnOldStoreGainsOwnersAndItsJobsAreTheAdmins) {
  TempDir tmp;
  const auto data = tmp.path() / "data";
  std::filesystem::create_directories(data);
  const auto store = data / "rcfd.sqlite";
  // The schema of version 2 as the server before users made it, with one job (its Idempotency-Key
  // set) and one uploaded database.
  const std::string oldJob = "0123456789abcdef0123456789abcdef", oldDb = "fedcba9876543210fedcba9876543210";
  const std::string schema = R"sql(
CREATE TABLE schema_version (version INTEGER NOT NULL);
INSERT INTO schema_version(version) VALUES(2);
CREATE TABLE jobs (
  seq INTEGER PRIMARY KEY AUTOINCREMENT, id TEXT NOT NULL UNIQUE, kind TEXT NOT NULL, state TEXT NOT NULL,
  request TEXT NOT NULL, idempotency_key TEXT UNIQUE, body_hash TEXT NOT NULL, database_ref TEXT,
  progress REAL NOT NULL DEFAULT 0, sim_time REAL, wall_time REAL, eta_s REAL, created_at TEXT NOT NULL,
  started_at TEXT, finished_at TEXT, updated_at TEXT NOT NULL, error TEXT, attempt INTEGER NOT NULL DEFAULT 0);
CREATE INDEX jobs_by_state ON jobs(state, seq);
CREATE INDEX jobs_by_kind ON jobs(kind, seq);
CREATE TABLE job_events (id INTEGER PRIMARY KEY AUTOINCREMENT, job_id TEXT NOT NULL REFERENCES jobs(id),
  at TEXT NOT NULL, from_state TEXT, to_state TEXT NOT NULL, reason TEXT);
CREATE INDEX job_events_by_job ON job_events(job_id, id);
CREATE TABLE summaries (job_id TEXT PRIMARY KEY REFERENCES jobs(id), summary TEXT NOT NULL);
CREATE TABLE coverage_bins (job_id TEXT NOT NULL REFERENCES jobs(id), bin INTEGER NOT NULL, lower REAL NOT NULL,
  upper REAL NOT NULL, count REAL NOT NULL, PRIMARY KEY (job_id, bin));
CREATE TABLE databases (id TEXT PRIMARY KEY, path TEXT NOT NULL, bytes INTEGER NOT NULL, frames INTEGER NOT NULL,
  created_at TEXT NOT NULL);
)sql";
  {
    sqlite3* handle = nullptr;
    ASSERT_EQ(sqlite3_open(store.c_str(), &handle), SQLITE_OK);
    char* message = nullptr;
    ASSERT_EQ(sqlite3_exec(handle, schema.c_str(), nullptr, nullptr, &message), SQLITE_OK) << message;
    const std::string at = "2026-01-01T00:00:00.000Z";
    const auto run = [&](const std::string& sql, const std::vector<std::string>& values) {
      sqlite3_stmt* stmt = nullptr;
      ASSERT_EQ(sqlite3_prepare_v2(handle, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK) << sql;
      for (std::size_t i = 0; i < values.size(); ++i)
        sqlite3_bind_text(stmt, int(i + 1), values[i].c_str(), -1, SQLITE_TRANSIENT);
      EXPECT_EQ(sqlite3_step(stmt), SQLITE_DONE) << sql;
      sqlite3_finalize(stmt);
    };
    run("INSERT INTO jobs(id, kind, state, request, idempotency_key, body_hash, created_at, updated_at) "
        "VALUES(?1, 'database', 'QUEUED', ?2, 'old-key', '0000000000000000', ?3, ?3)",
        {oldJob, databaseJob(5).dump(), at});
    run("INSERT INTO job_events(job_id, at, to_state, reason) VALUES(?1, ?2, 'QUEUED', 'submitted')", {oldJob, at});
    run("INSERT INTO databases VALUES(?1, ?2, 1024, 24, ?3)", {oldDb, "/nowhere/" + oldDb + ".h5", at});
    sqlite3_close(handle);
  }
  {
    ServerProcess server(data, "single-token");
    const auto health = server.get("/v1/health").json();
    EXPECT_EQ(health.at("schema_version"), 5);  // users (3), the running job's phase (4), the Slurm job id (5)
    EXPECT_EQ(health.at("version"), RCFD_VERSION);  // the project's, from CMakeLists.txt
    const auto job = server.get("/v1/jobs/" + oldJob);
    ASSERT_EQ(job.status, 200) << job.body;
    EXPECT_EQ(job.json().at("owner"), "admin");
    EXPECT_TRUE(job.json().at("progress").at("phase").is_null()) << job.body;
    EXPECT_EQ(server.get("/v1/databases/" + oldDb).json().at("owner"), "admin");
    // The old Idempotency-Key is still the (single token's) admin's: another body under it is refused
    // naming the old job.
    const auto reused = server.post("/v1/jobs", databaseJob(6).dump(), {{"Idempotency-Key", "old-key"}});
    EXPECT_EQ(reused.status, 422) << reused.body;
    EXPECT_NE(reused.body.find(oldJob), std::string::npos) << reused.body;
    EXPECT_EQ(server.post("/v1/jobs", databaseJob(6).dump()).json().at("owner"), "admin");
  }
  EXPECT_EQ(sqliteInt(store, "SELECT version FROM schema_version"), 5);
  EXPECT_EQ(sqliteInt(store, "SELECT COUNT(*) FROM jobs WHERE owner = 'admin'"), 2);
  EXPECT_EQ(sqliteInt(store, "SELECT COUNT(*) FROM databases WHERE owner = 'admin'"), 1);

  // With named users the old jobs are the admin's: not a plain user's to see, every admin's.
  writeOwnerOnly(tmp.path() / "users", "alice user " + hexOf("alice-t") + "\nroot admin " + hexOf("root-t") + "\n");
  ServerProcess named(data, "", {"--workers", "0", "--users-file", (tmp.path() / "users").string()});
  EXPECT_EQ(httpRequest(named.port(), http::verb::get, "/v1/jobs/" + oldJob, "alice-t").status, 404);
  EXPECT_TRUE(httpRequest(named.port(), http::verb::get, "/v1/jobs", "alice-t").json().at("jobs").empty());
  EXPECT_EQ(httpRequest(named.port(), http::verb::get, "/v1/jobs/" + oldJob, "root-t").json().at("owner"), "admin");
  EXPECT_EQ(httpRequest(named.port(), http::verb::get, "/v1/jobs", "root-t").json().at("jobs").size(), 2u);
}

}  // namespace
