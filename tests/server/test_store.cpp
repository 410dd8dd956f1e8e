// The SQLite store through the real server: migrations from an empty file, idempotent on restart,
// jobs survive a restart, WAL mode; plus a solver that cannot be executed fails only its job.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "ServerFixture.hpp"

using namespace rcfd::test;

namespace {

/// Reads one integer with the sqlite3 C API (the test's own connection, not the server's code).
long long queryInt(const std::filesystem::path& db, const std::string& sql) {
  sqlite3* handle = nullptr;
  EXPECT_EQ(sqlite3_open_v2(db.c_str(), &handle, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(handle, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK) << sql;
  long long value = -1;
  if (sqlite3_step(stmt) == SQLITE_ROW) value = sqlite3_column_int64(stmt, 0);
  sqlite3_finalize(stmt);
  sqlite3_close(handle);
  return value;
}

std::string queryText(const std::filesystem::path& db, const std::string& sql) {
  sqlite3* handle = nullptr;
  sqlite3_open_v2(db.c_str(), &handle, SQLITE_OPEN_READONLY, nullptr);
  sqlite3_stmt* stmt = nullptr;
  sqlite3_prepare_v2(handle, sql.c_str(), -1, &stmt, nullptr);
  std::string value;
  if (sqlite3_step(stmt) == SQLITE_ROW && sqlite3_column_text(stmt, 0))
    value = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
  sqlite3_finalize(stmt);
  sqlite3_close(handle);
  return value;
}

TEST(Store, MigratesAnEmptyFileAndIsIdempotentOnRestart) {
  TempDir tmp;
  const auto data = tmp.path() / "data";
  std::filesystem::create_directories(data);
  { std::ofstream empty(data / "rcfd.sqlite"); }  // an existing, empty file
  const auto dbPath = data / "rcfd.sqlite";
  int version = 0;
  std::string id;
  {
    ServerProcess server(data, "tok");
    version = server.get("/v1/health").json().at("schema_version");
    EXPECT_GE(version, 2);
    id = server.post("/v1/jobs", databaseJob().dump()).json().at("id");
  }
  EXPECT_EQ(queryInt(dbPath, "SELECT version FROM schema_version"), version);
  EXPECT_EQ(queryInt(dbPath, "SELECT COUNT(*) FROM schema_version"), 1);
  for (const char* table : {"jobs", "job_events", "summaries", "coverage_bins", "databases"})
    EXPECT_EQ(queryInt(dbPath, std::string("SELECT COUNT(*) FROM sqlite_master WHERE type='table' AND name='") +
                                   table + "'"),
              1)
        << table;
  EXPECT_EQ(queryText(dbPath, "PRAGMA journal_mode"), "wal");

  // Restart: no migration runs again, the job is still there and still QUEUED.
  ServerProcess again(data, "tok");
  EXPECT_EQ(again.get("/v1/health").json().at("schema_version"), version);
  const auto job = again.get("/v1/jobs/" + id);
  ASSERT_EQ(job.status, 200);
  EXPECT_EQ(job.json().at("state"), "QUEUED");
  EXPECT_EQ(queryInt(dbPath, "SELECT COUNT(*) FROM jobs"), 1);
}

TEST(Store, RefusesAStoreFromANewerServer) {
  TempDir tmp;
  const auto data = tmp.path() / "data";
  { ServerProcess server(data, "tok"); }
  sqlite3* handle = nullptr;
  ASSERT_EQ(sqlite3_open((data / "rcfd.sqlite").c_str(), &handle), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(handle, "UPDATE schema_version SET version = 999", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(handle);
  EXPECT_THROW(ServerProcess(data, "tok"), std::runtime_error);
}

TEST(Store, GeneratesATokenWhenNoneIsConfigured) {
  TempDir tmp;
  const auto data = tmp.path() / "data";
  std::filesystem::create_directories(data);
  // Start without --token-file and without RCFD_TOKEN: the server writes DIR/token.
  ServerCommand command({(binaryDir() / "rcfd-server").string(), "--data-dir", data.string(), "--listen",
                         "127.0.0.1:0", "--workers", "0"});
  command.stderrFile = "/dev/null";
  command.unsetEnvironment = {"RCFD_TOKEN"};
  ServerChild server(std::move(command));
  const std::string& line = server.firstLine();
  ASSERT_EQ(line.rfind("listening on http://127.0.0.1:", 0), 0u) << line;
  const auto port = server.port();
  std::ifstream in(data / "token");
  std::string token;
  in >> token;
  EXPECT_EQ(token.size(), 32u);
  EXPECT_EQ(std::filesystem::status(data / "token").permissions() & std::filesystem::perms::others_read,
            std::filesystem::perms::none);
  EXPECT_EQ(httpRequest(port, boost::beast::http::verb::get, "/v1/jobs", token).status, 200);
  EXPECT_EQ(httpRequest(port, boost::beast::http::verb::get, "/v1/jobs", "x").status, 401);
  const int status = server.stop(SIGTERM);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

TEST(Store, GracefulShutdownOnSigtermExitsZero) {
  TempDir tmp;
  ServerProcess server(tmp.path() / "data", "tok");
  const int status = server.stop(SIGTERM);
  EXPECT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

TEST(Store, SolverThatCannotRunFailsOnlyItsJobWithAReason) {
  TempDir tmp;
  ServerProcess server(tmp.path() / "data", "tok",
                       {"--workers", "1", "--solver", (tmp.path() / "no-such-solver").string()});
  const std::string id = server.post("/v1/jobs", databaseJob().dump()).json().at("id");
  nlohmann::json job;
  for (int i = 0; i < 100; ++i) {
    job = server.get("/v1/jobs/" + id).json();
    if (job.at("state") == "FAILED") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(job.at("state"), "FAILED") << job.dump();
  EXPECT_NE(job.at("error").get<std::string>().find("could not be executed"), std::string::npos)
      << job.dump();
  EXPECT_EQ(job.at("attempt"), 1);
  // The server keeps serving and the log artifact explains the failure.
  const auto log = server.get("/v1/jobs/" + id + "/artifacts/solver.log");
  EXPECT_EQ(log.status, 200);
  EXPECT_NE(log.body.find("cannot execute"), std::string::npos);
  EXPECT_EQ(server.get("/v1/health").status, 200);
}

}  // namespace
