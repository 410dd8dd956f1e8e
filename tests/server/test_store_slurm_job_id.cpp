// The job store's migration to schema version 5 (the Slurm job of a job's attempt, docs/cluster.md),
// called directly: a store an older server left at version 4 keeps its jobs and gains the column.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <string>

#include "JobStore.hpp"
#include "ServerFixture.hpp"

using namespace rcfd::server;

namespace {

void execSql(const std::filesystem::path& path, const char* sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* message = nullptr;
  const int rc = sqlite3_exec(db, sql, nullptr, nullptr, &message);
  const std::string text = message ? message : "";
  sqlite3_free(message);
  sqlite3_close(db);
  ASSERT_EQ(rc, SQLITE_OK) << text;
}

}  // namespace

TEST(StoreSlurmJobId, AVersion4StoreKeepsItsJobsAndGainsTheSlurmJobId) {
  rcfd::test::TempDir tmp;
  const auto path = tmp.path() / "rcfd.sqlite";
  JobRecord job;
  job.id = "0123456789abcdef0123456789abcdef";
  job.kind = "spray";
  job.request = R"({"kind":"spray"})";
  job.bodyHash = "hash";
  job.owner = "alice";
  {
    JobStore store(path.string());
    ASSERT_TRUE(store.insertJob(job).created);
  }
  // The store as a server of schema version 4 left it.
  execSql(path, "ALTER TABLE jobs DROP COLUMN slurm_job_id; UPDATE schema_version SET version = 4");

  JobStore store(path.string());
  EXPECT_EQ(store.schemaVersion(), 5);
  auto kept = store.job(job.id);
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->state, state::queued);
  EXPECT_EQ(kept->owner, "alice");
  EXPECT_EQ(kept->slurmJobId, "");

  ASSERT_TRUE(store.markStarted(job.id, "submitting to Slurm as rcfd-x-1"));
  store.setSlurmJobId(job.id, "4711");
  EXPECT_EQ(store.job(job.id)->slurmJobId, "4711");
  EXPECT_EQ(store.events(job.id).back().reason, "submitting to Slurm as rcfd-x-1");
  // A new attempt forgets the previous attempt's Slurm job until its own is stored.
  ASSERT_TRUE(store.transition(job.id, state::running, state::queued, "requeued"));
  ASSERT_TRUE(store.markStarted(job.id));
  EXPECT_EQ(store.job(job.id)->slurmJobId, "");
  EXPECT_EQ(store.job(job.id)->attempt, 2);
  EXPECT_EQ(store.events(job.id).back().reason, "worker started");
}
