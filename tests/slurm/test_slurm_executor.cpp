// rcfd-server --executor slurm against a real single-node Slurm (tests/slurm/start-slurm.sh, a ctest
// fixture): a spray job to the end with the local executor's result, a cancel, a job past its time
// limit, a node set DOWN mid-job, and a kill -9 of the server mid-job. Each test starts its own server
// on loopback with its own data directory; the jobs are tiny spray jobs on the small analytic database
// of the server tests.

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "ServerFixture.hpp"
#include "SmallDatabase.hpp"

using namespace rcfd::test;
namespace fs = std::filesystem;

namespace {

constexpr long kTracers = 200;

const fs::path& clusterDir() {
  static const fs::path dir = RCFD_SLURM_DIR;
  return dir;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Runs a shell command line; returns its stdout (exit status in `status`).
std::string run(const std::string& command, int* status = nullptr) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int rc = ::pclose(pipe);
  if (status) *status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return out;
}

/// The Slurm jobs the cluster lists whose name starts with `prefix`: "ID STATE" lines.
std::vector<std::string> slurmJobsNamed(const std::string& prefix) {
  std::istringstream lines(run("squeue --noheader --states=all --format='%i %T %j'"));
  std::vector<std::string> out;
  for (std::string id, state, name; lines >> id >> state >> name;)
    if (name.rfind(prefix, 0) == 0) out.push_back(id + " " + state);
  return out;
}

/// The Slurm job id stored with the job in the server's SQLite store.
std::string storedSlurmJobId(const fs::path& dataDir, const std::string& id) {
  sqlite3* db = nullptr;
  std::string out;
  if (sqlite3_open_v2((dataDir / "rcfd.sqlite").c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db, "SELECT slurm_job_id FROM jobs WHERE id = ?1", -1, &s, nullptr);
    sqlite3_bind_text(s, 1, id.c_str(), -1, SQLITE_TRANSIENT);
    if (s && sqlite3_step(s) == SQLITE_ROW && sqlite3_column_text(s, 0))
      out = reinterpret_cast<const char*>(sqlite3_column_text(s, 0));
    sqlite3_finalize(s);
  }
  sqlite3_close(db);
  return out;
}

/// The rcfd-solve process running in `jobDir`, -1 if there is none (from /proc).
pid_t solverIn(const fs::path& jobDir) {
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string cmdline = readText(entry.path() / "cmdline");
    for (auto& c : cmdline)
      if (c == '\0') c = ' ';
    if (cmdline.find("rcfd-solve run") != std::string::npos &&
        cmdline.find(jobDir.string()) != std::string::npos) {
      const std::string stat = readText(entry.path() / "stat");
      const auto close = stat.rfind(')');
      if (close != std::string::npos && close + 2 < stat.size() && stat[close + 2] != 'Z') return std::stoi(name);
    }
  }
  return -1;
}

bool isFinal(const nlohmann::json& job) {
  const std::string s = job.at("state");
  return s == "SUCCEEDED" || s == "FAILED" || s == "CANCELLED";
}

/// The reasons of the job's events, one a line, for messages and searches.
std::string eventReasons(const ServerProcess& server, const std::string& id) {
  std::string out;
  const auto events = server.get("/v1/jobs/" + id + "/events").json();  // not a temporary in the for
  for (const auto& e : events.at("events")) {
    out += e.at("from").is_null() ? std::string("-") : e.at("from").get<std::string>();
    out += " -> " + e.at("to").get<std::string>() + ": " + e.at("reason").get<std::string>() + "\n";
  }
  return out;
}

class SlurmExecutor : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Started by the ctest fixture; started here when the executable is run by hand.
    const std::string script = (sourceDir() / "tests" / "slurm" / "start-slurm.sh").string();
    ::setenv("SLURM_CONF", (clusterDir() / "slurm.conf").c_str(), 1);
    int status = 1;
    if (fs::exists(clusterDir() / "ready")) run("scontrol ping > /dev/null 2>&1", &status);
    if (status != 0 && !fs::exists(clusterDir() / "unavailable"))
      std::system(("bash '" + script + "' '" + clusterDir().string() + "' start").c_str());
  }

  void SetUp() override {
    if (fs::exists(clusterDir() / "unavailable"))
      GTEST_SKIP() << "no Slurm to test with: " << readText(clusterDir() / "unavailable");
    ASSERT_TRUE(fs::exists(clusterDir() / "ready"))
        << "the test cluster did not start; see " << (clusterDir() / "log").string();
    ASSERT_TRUE(fs::exists(binaryDir() / "rcfd-solve")) << "build rcfd-solve first";
    node_ = readText(clusterDir() / "ready");
    node_.erase(node_.find_last_not_of(" \n") + 1);
    tmp_ = std::make_unique<TempDir>();
    scene_ = withTracers(quickScene(), kTracers);
    writeSmallDatabase(scene_, tmp_->path() / "db.h5");
  }

  void TearDown() override {
    // Whatever a failed test left: the node back in service, no job of this test's servers in Slurm.
    if (!node_.empty()) run("scontrol update nodename=" + node_ + " state=resume > /dev/null 2>&1");
    for (const auto& line : slurmJobsNamed("rcfd-"))
      run("scancel " + line.substr(0, line.find(' ')) + " > /dev/null 2>&1");
  }

  fs::path dataDir() const { return tmp_->path() / "data"; }
  fs::path jobDir(const std::string& id) const { return dataDir() / "jobs" / id; }

  std::unique_ptr<ServerProcess> startSlurmServer(std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {"--executor", "slurm", "--slurm-poll-interval", "1",
                                     "--solver", (binaryDir() / "rcfd-solve").string(), "--cancel-grace", "20"};
    args.insert(args.end(), extra.begin(), extra.end());
    return std::make_unique<ServerProcess>(dataDir(), "slurm-token", args);
  }

  std::string upload(const ServerProcess& server) {
    const auto r = httpRequest(server.port(), boost::beast::http::verb::post, "/v1/databases", server.token(),
                               readText(tmp_->path() / "db.h5"), {{"Content-Type", "application/x-hdf5"}});
    EXPECT_EQ(r.status, 201) << r.body;
    return r.json().at("id");
  }

  std::string submit(const ServerProcess& server, const nlohmann::json& job) {
    const auto r = server.post("/v1/jobs", job.dump());
    EXPECT_EQ(r.status, 202) << r.body;
    return r.json().at("id");
  }

  nlohmann::json sprayJob(const std::string& database, double duration, int seed) const {
    return {{"kind", "spray"}, {"scene", scene_}, {"database", database},
            {"duration", duration}, {"seed", seed}, {"checkpoint_interval", 0.05}};
  }

  template <class Predicate>
  nlohmann::json pollJob(const ServerProcess& server, const std::string& id, Predicate done,
                         std::chrono::seconds timeout = std::chrono::seconds(120)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    nlohmann::json job;
    while (std::chrono::steady_clock::now() < deadline) {
      job = server.get("/v1/jobs/" + id).json();
      if (done(job)) return job;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return job;
  }

  /// The job's solver once it has written its first checkpoint, frozen with SIGSTOP so that the job is
  /// still running whatever the machine's speed; -1 if none was seen in time.
  pid_t frozenSolverWithCheckpoint(const std::string& id) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(90);
    pid_t solver = -1;
    while (std::chrono::steady_clock::now() < deadline) {
      if (solver < 0) {
        solver = solverIn(jobDir(id));  // a scan of /proc: not in the tight loop below
        std::this_thread::sleep_for(std::chrono::milliseconds(solver < 0 ? 20 : 0));
        continue;
      }
      if (fs::exists(jobDir(id) / "checkpoint.h5")) {
        if (::kill(solver, SIGSTOP) == 0 && solverIn(jobDir(id)) == solver) return solver;
        ::kill(solver, SIGCONT);
        return -1;  // it ended before it could be frozen
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return -1;
  }

  /// A job whose server was killed (-9) while its solver ran in Slurm.
  struct OrphanedJob {
    std::string id, slurmJobId;
  };
  OrphanedJob killServerMidJob(int seed) {
    OrphanedJob orphan;
    auto server = startSlurmServer();
    orphan.id = submit(*server, sprayJob(upload(*server), 12.0, seed));
    const pid_t solver = frozenSolverWithCheckpoint(orphan.id);
    EXPECT_GT(solver, 0) << "no solver with a checkpoint was seen; " << eventReasons(*server, orphan.id);
    orphan.slurmJobId = storedSlurmJobId(dataDir(), orphan.id);
    server->stop(SIGKILL);
    if (solver > 0) ::kill(solver, SIGCONT);
    return orphan;
  }
  /// A new server follows the orphan's Slurm job to the end: its first attempt, nothing submitted again.
  std::unique_ptr<ServerProcess> expectFollowedToTheEnd(const OrphanedJob& orphan) {
    auto server = startSlurmServer();
    const auto done = pollJob(*server, orphan.id, isFinal);
    EXPECT_EQ(done.at("state"), "SUCCEEDED") << done.dump(2) << eventReasons(*server, orphan.id);
    EXPECT_EQ(done.at("attempt"), 1);
    EXPECT_EQ(storedSlurmJobId(dataDir(), orphan.id), orphan.slurmJobId);
    EXPECT_EQ(slurmJobsNamed("rcfd-" + orphan.id), std::vector<std::string>{orphan.slurmJobId + " COMPLETED"});
    return server;
  }

  std::unique_ptr<TempDir> tmp_;
  nlohmann::json scene_;
  std::string node_;
};

}  // namespace

// The same spray job under Slurm and under the local executor: the same summary numbers. The Slurm job
// id is stored with the job, and Slurm ran it under the job's name.
TEST_F(SlurmExecutor, SprayJobRunsToTheEndWithTheLocalExecutorsResult) {
  nlohmann::json slurmResult, localResult;
  std::string id;
  {
    auto server = startSlurmServer();
    const std::string db = upload(*server);
    id = submit(*server, sprayJob(db, 0.5, 1));
    const auto done = pollJob(*server, id, isFinal);
    ASSERT_EQ(done.at("state"), "SUCCEEDED") << done.dump(2) << eventReasons(*server, id);
    EXPECT_EQ(done.at("attempt"), 1);
    EXPECT_EQ(done.at("progress").at("fraction"), 1.0);
    slurmResult = server->get("/v1/jobs/" + id + "/result").json();
    EXPECT_NE(eventReasons(*server, id).find("submitting to Slurm as rcfd-" + id + "-1"), std::string::npos)
        << eventReasons(*server, id);
  }
  const std::string slurmJobId = storedSlurmJobId(dataDir(), id);
  ASSERT_FALSE(slurmJobId.empty());
  EXPECT_EQ(slurmJobsNamed("rcfd-" + id), std::vector<std::string>{slurmJobId + " COMPLETED"});
  EXPECT_TRUE(fs::exists(jobDir(id) / ("slurm-" + slurmJobId + ".exit")));
  {
    TempDir localTmp;
    ServerProcess local(localTmp.path() / "data", "local-token",
                        {"--executor", "local", "--workers", "1", "--solver", (binaryDir() / "rcfd-solve").string()});
    const auto r = httpRequest(local.port(), boost::beast::http::verb::post, "/v1/databases", local.token(),
                               readText(tmp_->path() / "db.h5"), {{"Content-Type", "application/x-hdf5"}});
    ASSERT_EQ(r.status, 201) << r.body;
    const std::string localId = submit(local, sprayJob(r.json().at("id"), 0.5, 1));
    ASSERT_EQ(pollJob(local, localId, isFinal).at("state"), "SUCCEEDED");
    localResult = local.get("/v1/jobs/" + localId + "/result").json();
  }
  EXPECT_EQ(slurmResult.at("coverage"), localResult.at("coverage"));
  EXPECT_EQ(slurmResult.at("steps"), localResult.at("steps"));
  EXPECT_EQ(slurmResult.at("sim_time_s"), localResult.at("sim_time_s"));
}

// A cancel reaches the solver as SIGTERM through the batch shell: it checkpoints, and the job ends
// CANCELLED with its checkpoint; meanwhile its progress came from the job directory.
TEST_F(SlurmExecutor, CancelCheckpointsAndEndsCancelled) {
  auto server = startSlurmServer();
  const std::string id = submit(*server, sprayJob(upload(*server), 1000.0, 2));  // would run for hours
  const auto running = pollJob(*server, id, [&](const nlohmann::json& j) {
    return j.at("progress").at("fraction").get<double>() > 0 && fs::exists(jobDir(id) / "checkpoint.h5");
  });
  ASSERT_EQ(running.at("state"), "RUNNING") << running.dump(2) << eventReasons(*server, id);
  const std::string slurmJobId = storedSlurmJobId(dataDir(), id);
  ASSERT_EQ(slurmJobsNamed("rcfd-" + id), std::vector<std::string>{slurmJobId + " RUNNING"});

  ASSERT_EQ(server->post("/v1/jobs/" + id + ":cancel", "").status, 202);
  const auto done = pollJob(*server, id, isFinal, std::chrono::seconds(60));
  EXPECT_EQ(done.at("state"), "CANCELLED") << done.dump(2) << eventReasons(*server, id);
  EXPECT_NE(eventReasons(*server, id).find("CANCELLING -> CANCELLED: the solver checkpointed and stopped"),
            std::string::npos)
      << eventReasons(*server, id);
  EXPECT_EQ(readText(jobDir(id) / ("slurm-" + slurmJobId + ".exit")), "130\n");
  EXPECT_EQ(solverIn(jobDir(id)), -1);
}

// A solver that fails on the node: Slurm ends the batch job FAILED, and the job FAILS naming the Slurm
// state, the solver's exit and the end of its log. The failing solver is a script (--slurm-solver): the
// real one fails only on inputs the server already refuses at submission.
TEST_F(SlurmExecutor, ASolverThatFailsOnTheNodeEndsFailedWithSlurmsStateAndItsLog) {
  const auto failing = tmp_->path() / "failing-solver.sh";
  std::ofstream(failing) << "#!/bin/sh\necho 'error: the node has no scratch space' >&2\nexit 3\n";
  fs::permissions(failing, fs::perms::owner_all);
  auto server = startSlurmServer({"--slurm-solver", failing.string()});
  const std::string id = submit(*server, sprayJob(upload(*server), 0.5, 8));
  const auto done = pollJob(*server, id, isFinal, std::chrono::seconds(60));
  ASSERT_EQ(done.at("state"), "FAILED") << done.dump(2) << eventReasons(*server, id);
  const std::string error = done.at("error");
  const std::string slurmJobId = storedSlurmJobId(dataDir(), id);
  EXPECT_NE(error.find("Slurm job " + slurmJobId + " ended FAILED (the run failed (exit 3))"), std::string::npos)
      << error;
  EXPECT_NE(error.find("error: the node has no scratch space"), std::string::npos) << error;
  EXPECT_EQ(done.at("attempt"), 1);  // a failure is not a reason to submit again
}

// A job past its Slurm time limit (one minute, the shortest Slurm has) ends TIMEOUT in Slurm and is
// submitted again; the second attempt resumes from the checkpoint and finishes. The first attempt's
// solver is frozen once it has checkpointed, so that it outlasts the limit however fast the machine is,
// while the job itself stays short enough for the second attempt to finish within the same limit.
TEST_F(SlurmExecutor, JobPastItsTimeLimitIsRequeuedAndFinishesFromItsCheckpoint) {
  auto server = startSlurmServer({"--slurm-time", "spray=1", "--slurm-signal-lead", "0", "--slurm-requeues", "1"});
  const std::string id = submit(*server, sprayJob(upload(*server), 12.0, 3));
  const pid_t solver = frozenSolverWithCheckpoint(id);
  ASSERT_GT(solver, 0) << "no solver with a checkpoint was seen; " << eventReasons(*server, id);
  const std::string firstSlurmJob = storedSlurmJobId(dataDir(), id);
  const auto requeued = pollJob(*server, id, [](const nlohmann::json& j) { return j.at("attempt") == 2; },
                                std::chrono::seconds(150));
  ::kill(solver, SIGCONT);  // Slurm has killed it by now; in case not, it must not stay frozen
  ASSERT_EQ(requeued.at("attempt"), 2) << requeued.dump(2) << eventReasons(*server, id);
  const auto done = pollJob(*server, id, isFinal, std::chrono::seconds(60));
  EXPECT_EQ(done.at("state"), "SUCCEEDED") << done.dump(2) << eventReasons(*server, id);
  const std::string events = eventReasons(*server, id);
  EXPECT_NE(events.find("RUNNING -> QUEUED: Slurm job " + firstSlurmJob +
                        " ended TIMEOUT; submitted again to resume from its checkpoint (requeue 1 of 1)"),
            std::string::npos)
      << events;
  EXPECT_NE(readText(jobDir(id) / "solver.log").find("resumed from"), std::string::npos)
      << "the second attempt did not resume: " << readText(jobDir(id) / "solver.log");
  EXPECT_EQ(slurmJobsNamed("rcfd-" + id).size(), 2u);
}

// Slurm's warning ahead of the time limit (--slurm-signal-lead): the batch shell passes SIGTERM on, the
// solver checkpoints and exits 130 before the limit, and the job is submitted again and resumes. A job
// far too long for its limit meets the warning in every attempt: past --slurm-requeues it FAILS, saying so.
TEST_F(SlurmExecutor, TimeLimitWarningCheckpointsAndResumesUntilTheRequeuesAreUsedUp) {
  auto server = startSlurmServer({"--slurm-time", "spray=1", "--slurm-signal-lead", "55", "--slurm-requeues", "1"});
  const std::string id = submit(*server, sprayJob(upload(*server), 1000.0, 6));
  const auto done = pollJob(*server, id, isFinal, std::chrono::seconds(150));
  ASSERT_EQ(done.at("state"), "FAILED") << done.dump(2) << eventReasons(*server, id);
  EXPECT_EQ(done.at("attempt"), 2);
  const std::string events = eventReasons(*server, id);
  EXPECT_NE(events.find("after the solver checkpointed on SIGTERM (the time limit's warning); submitted again to "
                        "resume from its checkpoint (requeue 1 of 1)"),
            std::string::npos)
      << events;
  EXPECT_NE(done.at("error").get<std::string>().find("not submitted again after 1 requeue(s)"), std::string::npos)
      << done.dump(2);
  const std::string secondSlurmJob = storedSlurmJobId(dataDir(), id);
  EXPECT_EQ(readText(jobDir(id) / ("slurm-" + secondSlurmJob + ".exit")), "130\n");
  EXPECT_TRUE(fs::exists(jobDir(id) / ("slurm-" + secondSlurmJob + ".term")));
  EXPECT_NE(readText(jobDir(id) / "solver.log").find("resumed from"), std::string::npos)
      << "the second attempt did not resume: " << readText(jobDir(id) / "solver.log");
}

// The node goes DOWN under a running job: Slurm ends it NODE_FAIL, the server submits it again, and
// once the node is back (state=resume) the job resumes from its checkpoint and finishes.
TEST_F(SlurmExecutor, NodeDownMidJobRequeuesAndTheJobFinishesWhenTheNodeIsBack) {
  auto server = startSlurmServer();
  const std::string id = submit(*server, sprayJob(upload(*server), 12.0, 4));
  const pid_t solver = frozenSolverWithCheckpoint(id);
  ASSERT_GT(solver, 0) << "no solver with a checkpoint was seen; " << eventReasons(*server, id);
  const std::string firstSlurmJob = storedSlurmJobId(dataDir(), id);
  run("scontrol update nodename=" + node_ + " state=down reason=rcfd-test");
  ::kill(solver, SIGCONT);  // it meets Slurm's SIGTERM
  // Submitted again, and pending in Slurm while the node is down.
  const auto requeued = pollJob(*server, id, [](const nlohmann::json& j) { return j.at("attempt") == 2; },
                                std::chrono::seconds(60));
  ASSERT_EQ(requeued.at("attempt"), 2) << requeued.dump(2) << eventReasons(*server, id);
  EXPECT_EQ(requeued.at("state"), "RUNNING");
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const std::string secondSlurmJob = storedSlurmJobId(dataDir(), id);
  EXPECT_EQ(slurmJobsNamed("rcfd-" + id + "-2"), std::vector<std::string>{secondSlurmJob + " PENDING"});
  run("scontrol update nodename=" + node_ + " state=resume");
  const auto done = pollJob(*server, id, isFinal);
  EXPECT_EQ(done.at("state"), "SUCCEEDED") << done.dump(2) << eventReasons(*server, id);
  EXPECT_NE(eventReasons(*server, id).find("Slurm job " + firstSlurmJob + " ended NODE_FAIL; submitted again"),
            std::string::npos)
      << eventReasons(*server, id);
}

// kill -9 of the server mid-job: the job goes on in Slurm, the restarted server finds it by its stored
// Slurm id and follows it to the end, and nothing is submitted twice.
TEST_F(SlurmExecutor, ServerKilledMidJobFollowsTheSameSlurmJobToTheEnd) {
  const OrphanedJob orphan = killServerMidJob(5);
  ASSERT_FALSE(orphan.slurmJobId.empty());
  EXPECT_EQ(slurmJobsNamed("rcfd-" + orphan.id), std::vector<std::string>{orphan.slurmJobId + " RUNNING"});
  const auto server = expectFollowedToTheEnd(orphan);
  EXPECT_NE(server->stderrText().find("following 1 job(s) already in Slurm"), std::string::npos)
      << server->stderrText();
}

// A server killed between sbatch and storing its answer left the job RUNNING without a Slurm id (made
// here by clearing the stored id): the next server finds the Slurm job by its name (rcfd-ID-ATTEMPT),
// stores its id and follows it; nothing is submitted again.
TEST_F(SlurmExecutor, ServerKilledBeforeStoringTheSlurmIdFindsTheJobByItsName) {
  const OrphanedJob orphan = killServerMidJob(7);
  ASSERT_FALSE(orphan.slurmJobId.empty());
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dataDir() / "rcfd.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE jobs SET slurm_job_id = NULL", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  ASSERT_EQ(storedSlurmJobId(dataDir(), orphan.id), "");
  expectFollowedToTheEnd(orphan);
}
