// End to end with the real solver: rcfd-server runs `rcfd-solve run` children. A field database is
// written with rcfd::writeAnalyticDatabase (SmallDatabase.hpp) and uploaded with the client, or made
// by a database job; a spray job runs on it, and the coverage downloaded as CSV and as HDF5 equals the
// histogram in the job's result.h5. Also: kill -9 of a solver fails only its job;
// kill -9 of the server, restart, and the job resumes from its checkpoint to the same result.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <sstream>

#include "ClientRunner.hpp"
#include "ServerFixture.hpp"
#include "SmallDatabase.hpp"

using namespace rcfd::test;

namespace {

constexpr long kTracers = 200;

std::vector<double> readDoubles(hid_t file, const char* name) {
  const hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
  if (set < 0) return {};
  const hid_t space = H5Dget_space(set);
  const auto n = H5Sget_simple_extent_npoints(space);
  std::vector<double> values(static_cast<std::size_t>(n));
  H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Sclose(space);
  H5Dclose(set);
  return values;
}

struct Histogram {
  std::vector<double> edges, counts;
};

Histogram readH5(const std::filesystem::path& path, const char* edges, const char* counts) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(file, 0) << path;
  Histogram h{readDoubles(file, edges), readDoubles(file, counts)};
  H5Fclose(file);
  return h;
}

Histogram readCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "lower,upper,count");
  Histogram h;
  while (std::getline(in, line)) {
    double lo, up, count;
    char c1, c2;
    std::istringstream row(line);
    row >> lo >> c1 >> up >> c2 >> count;
    if (h.edges.empty()) h.edges.push_back(lo);
    EXPECT_EQ(h.edges.back(), lo);
    h.edges.push_back(up);
    h.counts.push_back(count);
  }
  return h;
}

/// Runs the client against `server`, without ClientRunner's hang limit: `submit --wait` lasts as long
/// as a real solve, which on a loaded machine may take longer.
Run client(const ServerProcess& server, std::vector<std::string> args) {
  args.insert(args.begin(), {"--server", server.url(), "--token", server.token()});
  return runClient(std::move(args), {}, std::chrono::seconds(0));
}

/// Polls until the job's state satisfies `done` (or the timeout passes); returns the last resource.
template <class Predicate>
nlohmann::json pollJob(const ServerProcess& server, const std::string& id, Predicate done,
                       std::chrono::seconds timeout = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  nlohmann::json job;
  while (std::chrono::steady_clock::now() < deadline) {
    job = server.get("/v1/jobs/" + id).json();
    if (done(job)) return job;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return job;
}

bool isFinal(const nlohmann::json& job) {
  const std::string s = job.at("state");
  return s == "SUCCEEDED" || s == "FAILED" || s == "CANCELLED";
}

/// Child processes of `parent` (from /proc).
std::vector<pid_t> childrenOf(pid_t parent) {
  std::vector<pid_t> out;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string text((std::istreambuf_iterator<char>(stat)), {});
    const auto close = text.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(text.substr(close + 2));
    char state;
    pid_t ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent) out.push_back(std::stoi(name));
  }
  return out;
}

/// True while `pid` exists and is not a zombie (an orphan's zombie may wait for a non-reaping init).
/// The state letter of /proc/<path>/stat (R, S, T, Z, ...); 0 when the file is gone.
static char procState(const std::string& path) {
  std::ifstream stat("/proc/" + path + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), {});
  const auto close = text.rfind(')');
  return close != std::string::npos && close + 2 < text.size() ? text[close + 2] : 0;
}

bool processRunning(pid_t pid) {
  const char state = procState(std::to_string(pid));
  return state != 0 && state != 'Z';
}

/// Whether every thread of `pid` is stopped (group stop done): from then on a signal sent to it stays
/// pending until SIGCONT. Right after kill(SIGSTOP) it need not be: a thread that has not yet taken the
/// SIGSTOP takes a SIGTERM sent meanwhile first (the lower number), runs its handler, and only then stops.
static bool allThreadsStopped(pid_t pid) {
  const auto tasks = std::filesystem::path("/proc") / std::to_string(pid) / "task";
  std::error_code ec;
  bool any = false;
  for (const auto& task : std::filesystem::directory_iterator(tasks, ec)) {
    const char state = procState(std::to_string(pid) + "/task/" + task.path().filename().string());
    if (state != 'T' && state != 't') return false;
    any = true;
  }
  return any && !ec;
}

class EndToEnd : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(binaryDir() / "rcfd-solve"))
      GTEST_SKIP() << "build rcfd-solve first";
    tmp_ = std::make_unique<TempDir>();
    scene_ = withTracers(quickScene(), kTracers);
    writeSmallDatabase(scene_, tmp_->path() / "db.h5");
  }
  // Solvers at the server's niceness by default here: ctest -j runs other tests of the same session
  // beside these, and a niced solver would wait behind them (the suite's time, not what is tested).
  std::unique_ptr<ServerProcess> start(int workers, int workerNice = 0, int autoRetries = 1) {
    return std::make_unique<ServerProcess>(
        tmp_->path() / "data", "e2e-token",
        std::vector<std::string>{"--workers", std::to_string(workers), "--solver",
                                 (binaryDir() / "rcfd-solve").string(), "--shutdown-grace", "20",
                                 "--worker-nice", std::to_string(workerNice), "--auto-retries",
                                 std::to_string(autoRetries)});
  }
  std::string upload(const ServerProcess& server) {
    const auto r = client(server, {"upload", (tmp_->path() / "db.h5").string()});
    EXPECT_EQ(r.code, 0) << r.err;
    return r.out.substr(0, r.out.find('\n'));
  }
  std::string submit(const ServerProcess& server, const nlohmann::json& job) {
    const auto r = server.post("/v1/jobs", job.dump());
    EXPECT_EQ(r.status, 202) << r.body;
    return r.json().at("id");
  }
  nlohmann::json sprayJob(const std::string& database, double duration, int seed = 1) const {
    return {{"kind", "spray"}, {"scene", scene_}, {"database", database},
            {"duration", duration}, {"seed", seed}, {"checkpoint_interval", 0.05}};
  }
  std::unique_ptr<TempDir> tmp_;
  nlohmann::json scene_;
};

TEST_F(EndToEnd, UploadSprayCoverageCsvAndH5EqualResultH5) {
  auto server = start(1);
  const std::string db = upload(*server);
  ASSERT_EQ(db.size(), 32u);
  std::ofstream(tmp_->path() / "spray.json") << sprayJob(db, 0.25).dump(2);
  const auto submitted = client(*server, {"submit", (tmp_->path() / "spray.json").string(), "--wait",
                                          "--interval", "0.2"});
  ASSERT_EQ(submitted.code, 0) << submitted.err << server->stderrText();
  const std::string id = submitted.out.substr(0, submitted.out.find('\n'));
  EXPECT_NE(submitted.err.find("SUCCEEDED"), std::string::npos) << submitted.err;
  EXPECT_EQ(submitted.out, id + "\n");  // stdout is only the id, so scripts can capture it

  const auto job = server->get("/v1/jobs/" + id).json();
  ASSERT_EQ(job.at("state"), "SUCCEEDED") << job.dump(2);
  EXPECT_DOUBLE_EQ(job.at("progress").at("fraction").get<double>(), 1.0);
  // The phase belongs to a running job.
  EXPECT_TRUE(job.at("progress").at("phase").is_null()) << job.dump(2);
  EXPECT_TRUE(job.at("progress").at("phase_fraction").is_null()) << job.dump(2);
  const auto result = client(*server, {"result", id});
  ASSERT_EQ(result.code, 0);
  EXPECT_EQ(nlohmann::json::parse(result.out).at("kind"), "spray");

  const auto dir = tmp_->path();
  ASSERT_EQ(client(*server, {"coverage", id, "--format", "csv", "-o", (dir / "c.csv").string()}).code, 0);
  ASSERT_EQ(client(*server, {"coverage", id, "--format", "h5", "-o", (dir / "c.h5").string()}).code, 0);
  ASSERT_EQ(client(*server, {"download", id, "result.h5", "-o", (dir / "r.h5").string()}).code, 0);
  const Histogram reference = readH5(dir / "r.h5", "/coverage/histogram_edges", "/coverage/histogram_counts");
  ASSERT_FALSE(reference.counts.empty());
  const Histogram csv = readCsv(dir / "c.csv");
  const Histogram h5 = readH5(dir / "c.h5", "/edges", "/counts");
  EXPECT_EQ(csv.edges, reference.edges);
  EXPECT_EQ(csv.counts, reference.counts);
  EXPECT_EQ(h5.edges, reference.edges);
  EXPECT_EQ(h5.counts, reference.counts);
  double tracers = 0;
  for (double c : reference.counts) tracers += c;
  EXPECT_EQ(tracers, double(kTracers));  // every tracer is in one bin

  // Merged bins keep the total; the artifacts list names what the job wrote.
  if (reference.counts.size() % 2 == 0) {
    const auto merged = server->get("/v1/jobs/" + id + "/coverage?format=json&bins=" +
                                    std::to_string(reference.counts.size() / 2)).json();
    double total = 0;
    for (const auto& c : merged.at("counts")) total += c.get<double>();
    EXPECT_EQ(total, tracers);
  }
  const auto artifacts = job.at("artifacts");
  EXPECT_NE(std::find(artifacts.begin(), artifacts.end(), "result.h5"), artifacts.end());
  EXPECT_NE(std::find(artifacts.begin(), artifacts.end(), "summary.json"), artifacts.end());
  // The ParaView sidecar of result.h5 downloads beside it and names it by relative path.
  EXPECT_NE(std::find(artifacts.begin(), artifacts.end(), "result.xmf"), artifacts.end());
  const Reply sidecar = server->get("/v1/jobs/" + id + "/artifacts/result.xmf");
  EXPECT_EQ(sidecar.status, 200);
  EXPECT_EQ(sidecar.header("content-type"), "application/xml");
  EXPECT_NE(sidecar.body.find("result.h5:/"), std::string::npos);
}

/// The nice value of a process (/proc/PID/stat field 19).
int niceOf(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), {});
  std::istringstream rest(text.substr(text.rfind(')') + 2));
  std::string field;
  for (int i = 3; i <= 19; ++i) rest >> field;
  return std::stoi(field);
}

TEST_F(EndToEnd, KillingOneSolverFailsOnlyItsJob) {
  auto server = start(2, 5, 0);  // the solvers run 5 nicer than the server; no automatic retry
  const std::string db = upload(*server);
  const std::string victim = submit(*server, sprayJob(db, 1000.0, 1));  // far too long to finish
  const std::string other = submit(*server, sprayJob(db, 0.2, 2));
  const auto running = pollJob(*server, victim, [](const nlohmann::json& j) {
    return j.at("state") == "RUNNING" && j.at("progress").at("fraction").get<double>() > 0;
  });
  ASSERT_EQ(running.at("state"), "RUNNING") << running.dump(2) << server->stderrText();
  // Find the victim's solver: the child whose command line names the victim's job folder.
  pid_t victimPid = -1;
  for (pid_t child : childrenOf(server->pid())) {
    std::ifstream cmd("/proc/" + std::to_string(child) + "/cmdline");
    std::string line((std::istreambuf_iterator<char>(cmd)), {});
    if (line.find(victim) != std::string::npos) victimPid = child;
  }
  ASSERT_GT(victimPid, 0);
  EXPECT_EQ(niceOf(victimPid), std::min(19, niceOf(server->pid()) + 5));
  ASSERT_EQ(::kill(victimPid, SIGKILL), 0);
  const auto failed = pollJob(*server, victim, isFinal);
  EXPECT_EQ(failed.at("state"), "FAILED");
  EXPECT_NE(failed.at("error").get<std::string>().find("SIGKILL"), std::string::npos) << failed.dump(2);
  const auto fine = pollJob(*server, other, isFinal);
  EXPECT_EQ(fine.at("state"), "SUCCEEDED") << fine.dump(2);
  EXPECT_EQ(server->get("/v1/health").status, 200);
}

/// The solver (the server's only child) once the job has written a checkpoint; -1 if none within 30 s.
static pid_t solverWithCheckpoint(const ServerProcess& server, const std::filesystem::path& checkpoint) {
  for (int i = 0; i < 6000; ++i) {
    const auto solvers = childrenOf(server.pid());
    if (solvers.size() == 1 && std::filesystem::exists(checkpoint)) return solvers[0];
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return -1;
}

// A solver killed from outside (SIGKILL, as the out-of-memory killer does) is queued again once and
// resumes from its checkpoint; killed again, the job fails, and a retry through the API resumes it once
// more to the end (that a resume gives the uninterrupted result is ServerKilledMidJobResumesToTheSameResult).
TEST_F(EndToEnd, AKilledSolverIsRetriedFromItsCheckpointAutomaticallyAndOnRequest) {
  auto server = start(1, 0, 1);
  const std::string db = upload(*server);
  const std::string id = submit(*server, sprayJob(db, 4.0, 6));
  const auto checkpoint = tmp_->path() / "data" / "jobs" / id / "checkpoint.h5";
  pid_t solver = solverWithCheckpoint(*server, checkpoint);
  ASSERT_GT(solver, 0) << "no solver with a checkpoint was seen";
  ASSERT_EQ(::kill(solver, SIGKILL), 0);
  // The retry starts a new solver (attempt 2); kill that one too once it runs.
  const auto second = pollJob(*server, id, [](const nlohmann::json& j) {
    return j.at("state") == "RUNNING" && j.at("attempt").get<int>() == 2;
  });
  ASSERT_EQ(second.at("attempt"), 2) << second.dump(2);
  pid_t again = -1;
  for (int i = 0; i < 6000 && again < 0; ++i) {
    const auto solvers = childrenOf(server->pid());
    if (solvers.size() == 1 && solvers[0] != solver) again = solvers[0];
    else std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (again > 0) ::kill(again, SIGKILL);
  const auto failed = pollJob(*server, id, isFinal);
  if (failed.at("state") == "SUCCEEDED") GTEST_SKIP() << "the second attempt finished before it was killed";
  ASSERT_EQ(failed.at("state"), "FAILED") << failed.dump(2);
  EXPECT_NE(failed.at("error").get<std::string>().find("SIGKILL"), std::string::npos) << failed.dump(2);
  ASSERT_EQ(server->post("/v1/jobs/" + id + ":retry", "").status, 200);
  const auto done = pollJob(*server, id, isFinal, std::chrono::seconds(90));
  ASSERT_EQ(done.at("state"), "SUCCEEDED") << done.dump(2);
  EXPECT_EQ(done.at("attempt"), 3);
  const auto events = server->get("/v1/jobs/" + id + "/events").json().at("events");
  int automatic = 0, requested = 0;
  for (const auto& e : events) {
    const std::string reason = e.at("reason");
    automatic += reason.find("automatic retry") != std::string::npos;
    requested += reason.find("retry requested by admin; resumes from its checkpoint") != std::string::npos;
  }
  EXPECT_EQ(automatic, 1) << events.dump(2);
  EXPECT_EQ(requested, 1) << events.dump(2);
}

/// The server's one solver, stopped (SIGSTOP) once `checkpoint` exists, returned when all its threads
/// have stopped (or it has ended, which the callers check); -1 when none is seen within 30 s.
pid_t freezeSolverAtItsCheckpoint(pid_t server, const std::filesystem::path& checkpoint) {
  for (int i = 0; i < 6000; ++i) {
    const auto solvers = childrenOf(server);
    if (solvers.size() == 1 && std::filesystem::exists(checkpoint) && ::kill(solvers[0], SIGSTOP) == 0) {
      for (int j = 0; j < 2000 && processRunning(solvers[0]) && !allThreadsStopped(solvers[0]); ++j)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      return solvers[0];
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return -1;
}

/// Whether `sig` is pending for process `pid` (its own or its thread group's pending set in
/// /proc/PID/status): a stopped process holds a signal sent to it until it runs again.
bool signalPending(pid_t pid, int sig) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("SigPnd:", 0) != 0 && line.rfind("ShdPnd:", 0) != 0) continue;
    const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
    if (mask & (1ULL << (sig - 1))) return true;
  }
  return false;
}

// The job must still be running when the server dies, however fast the machine: once the solver has
// written its first checkpoint, the test freezes it (SIGSTOP), kills the server, and only then lets it go
// on (SIGCONT) to meet its PDEATHSIG. Waiting for a progress fraction instead raced the job's end: a
// 12 s job takes 1 s of wall time on a fast machine, one progress interval.
TEST_F(EndToEnd, ServerKilledMidJobResumesToTheSameResult) {
  std::string db, interrupted;
  pid_t solver = -1;
  {
    auto server = start(1);
    db = upload(*server);
    interrupted = submit(*server, sprayJob(db, 12.0, 5));
    solver = freezeSolverAtItsCheckpoint(server->pid(), tmp_->path() / "data" / "jobs" / interrupted / "checkpoint.h5");
    ASSERT_GT(solver, 0) << "no solver with a checkpoint was seen";
    const auto frozen = server->get("/v1/jobs/" + interrupted).json();
    const bool alive = processRunning(solver);  // not a zombie that finished before the SIGSTOP
    server->stop(SIGKILL);  // the solver gets SIGTERM from the kernel (PDEATHSIG) and checkpoints
    // Released before any assertion, so a failing one never leaves a stopped orphan behind.
    ASSERT_EQ(::kill(solver, SIGCONT), 0);
    ASSERT_TRUE(alive);
    ASSERT_EQ(frozen.at("state"), "RUNNING") << frozen.dump(2);
    ASSERT_LT(frozen.at("progress").at("fraction").get<double>(), 1.0) << frozen.dump(2);
  }
  // The orphaned solver writes its checkpoint and exits; only then may a new server take the job.
  for (int i = 0; i < 400 && processRunning(solver); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_FALSE(processRunning(solver)) << "the solver did not stop after the server died";
  ASSERT_TRUE(std::filesystem::exists(tmp_->path() / "data" / "jobs" / interrupted / "checkpoint.h5"));

  auto server = start(1);
  const auto resumed = pollJob(*server, interrupted, isFinal, std::chrono::seconds(90));
  ASSERT_EQ(resumed.at("state"), "SUCCEEDED") << resumed.dump(2);
  EXPECT_EQ(resumed.at("attempt"), 2);
  const std::string reference = submit(*server, sprayJob(db, 12.0, 5));
  ASSERT_EQ(pollJob(*server, reference, isFinal, std::chrono::seconds(90)).at("state"), "SUCCEEDED");
  const auto a = server->get("/v1/jobs/" + interrupted + "/result").json();
  const auto b = server->get("/v1/jobs/" + reference + "/result").json();
  EXPECT_EQ(a.at("coverage"), b.at("coverage"));
  EXPECT_EQ(a.at("steps"), b.at("steps"));
  EXPECT_EQ(a.at("sim_time_s"), b.at("sim_time_s"));
  const auto events = server->get("/v1/jobs/" + interrupted + "/events").json().at("events");
  bool requeued = false;
  for (const auto& e : events) requeued = requeued || (e.at("from") == "RUNNING" && e.at("to") == "QUEUED");
  EXPECT_TRUE(requeued) << events.dump(2);
}

// As above, the job must still run when the server is told to stop, however fast the machine: the
// solver is frozen once it has a checkpoint, the server gets SIGTERM, and the solver goes on only when
// the server's SIGTERM waits for it, so it cannot finish first.
TEST_F(EndToEnd, SigtermRequeuesTheRunningJobAndTheNextStartFinishesIt) {
  std::string id;
  {
    auto server = start(1);
    const std::string db = upload(*server);
    id = submit(*server, sprayJob(db, 12.0, 4));
    const pid_t solver = freezeSolverAtItsCheckpoint(server->pid(), tmp_->path() / "data" / "jobs" / id / "checkpoint.h5");
    ASSERT_GT(solver, 0) << "no solver with a checkpoint was seen";
    const auto running = server->get("/v1/jobs/" + id).json();
    const bool alive = processRunning(solver);
    ::kill(server->pid(), SIGTERM);
    for (int i = 0; i < 2000 && !signalPending(solver, SIGTERM); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    const bool told = signalPending(solver, SIGTERM);
    ::kill(solver, SIGCONT);  // released before any assertion: no stopped orphan is left behind
    const int status = server->stop(0);  // waits for the solver to checkpoint and the server to exit
    ASSERT_TRUE(alive);
    ASSERT_TRUE(told) << "the server did not pass SIGTERM to its solver";
    ASSERT_EQ(running.at("state"), "RUNNING") << running.dump(2);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << server->stderrText();
  }
  auto server = start(1);
  const auto done = pollJob(*server, id, isFinal, std::chrono::seconds(90));
  EXPECT_EQ(done.at("state"), "SUCCEEDED") << done.dump(2);
  EXPECT_EQ(done.at("attempt"), 2);
  const auto events = server->get("/v1/jobs/" + id + "/events").json().at("events");
  bool requeued = false;
  for (const auto& e : events)
    requeued = requeued || (e.at("from") == "RUNNING" && e.at("to") == "QUEUED" &&
                            e.at("reason").get<std::string>().find("shut down") != std::string::npos);
  EXPECT_TRUE(requeued) << events.dump(2);
}

// A solver that ignores its cancel (SIGTERM) is killed after --cancel-grace and the job ends CANCELLED
// with the reason. rcfd-solve itself stops on SIGTERM, so the hung solver is a script that ignores the
// signal and sleeps: the one misbehaving child this server's own solver cannot be made to be.
TEST_F(EndToEnd, ASolverThatIgnoresItsCancelIsKilledAfterTheGracePeriod) {
  const auto hung = tmp_->path() / "hung-solver.sh";
  std::ofstream(hung) << "#!/bin/sh\ntrap '' TERM\nexec sleep 600\n";
  std::filesystem::permissions(hung, std::filesystem::perms::owner_all);
  ServerProcess server(tmp_->path() / "data", "e2e-token",
                       {"--workers", "1", "--solver", hung.string(), "--cancel-grace", "1"});
  const std::string id = submit(server, databaseJob(5));
  ASSERT_EQ(pollJob(server, id, [](const nlohmann::json& j) { return j.at("state") == "RUNNING"; }).at("state"),
            "RUNNING");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the script has set its trap
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(server.post("/v1/jobs/" + id + ":cancel", "").status, 202);
  const auto done = pollJob(server, id, isFinal);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(done.at("state"), "CANCELLED") << done.dump(2);
  EXPECT_LT(waited, 5.0);
  EXPECT_GT(waited, 0.9);
  const auto events = server.get("/v1/jobs/" + id + "/events").json().at("events");
  bool killed = false;
  for (const auto& e : events) killed = killed || e.at("reason").get<std::string>().find("SIGKILL") != std::string::npos;
  EXPECT_TRUE(killed) << events.dump(2);
}

// A database job cancelled while its solver fills a large bed (23,000 parcels at dt_DEM = 1 us, minutes
// of filling in which one millisecond of simulated time takes over 10 s) ends CANCELLED within the 5 s
// the solver has to stop plus the worker's 1 s poll, by the solver's own stop: no SIGKILL escalation.
TEST_F(EndToEnd, CancelDuringTheDemFillEndsCancelledWithinSecondsWithoutSigkill) {
  auto server = start(1);
  const nlohmann::json scene = {
      {"name", "cancel-fill"},
      {"apparatus", {{"type", "box"}, {"size", {0.1, 0.3, 0.05}}}},
      {"grid", {{"cell_size", 0.01}}},
      {"gas", nlohmann::json::object()},
      {"particles", {{"diameter", 0.002}, {"density", 1040.0}}},
      {"process", {{"bed_mass", 0.1}}},
      {"dem", {{"time_step", 1e-6}, {"settle_time", 0.15}, {"ramp_time", 0.0}, {"warmup", 0.01},
               {"sample_rate", 200}, {"probe_rate", 1000}, {"sample_duration", 0.05}, {"reference_duration", 0.03}}},
      {"probes", {{{"name", "bed"}, {"position", {0.0025, 0.0025, 0.0075}}}}},
      {"effects", {"rolling_friction"}}};
  const std::string id = submit(*server, {{"kind", "database"}, {"scene", scene}, {"seed", 3}});
  // In the fill: the job resource names the phase, and the solver's DEM time and the fill's own
  // progress move from the first steps.
  const auto filling = pollJob(*server, id, [](const nlohmann::json& j) {
    const auto& p = j.at("progress");
    return j.at("state") == "RUNNING" && p.at("phase") == "fill" && p.at("sim_time").is_number() &&
           p.at("sim_time").get<double>() > 0.0;
  });
  ASSERT_EQ(filling.at("state"), "RUNNING") << filling.dump(2) << server->stderrText();
  EXPECT_GT(filling.at("progress").at("phase_fraction").get<double>(), 0.0) << filling.dump(2);
  EXPECT_GT(filling.at("progress").at("fraction").get<double>(), 0.0) << filling.dump(2);
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(server->post("/v1/jobs/" + id + ":cancel", "").status, 202);
  const auto done = pollJob(*server, id, isFinal);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  RecordProperty("seconds_to_cancelled", std::to_string(waited));
  EXPECT_EQ(done.at("state"), "CANCELLED") << done.dump(2);
  EXPECT_TRUE(done.at("progress").at("phase").is_null()) << done.dump(2);
  EXPECT_LT(waited, 5.0 + 1.0);
  const auto events = server->get("/v1/jobs/" + id + "/events").json().at("events");
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().at("reason"),
            "the solver stopped before its first checkpoint; a retry starts from the beginning")
      << events.dump(2);
  for (const auto& e : events) EXPECT_EQ(e.dump().find("SIGKILL"), std::string::npos) << events.dump(2);
  std::ifstream log(tmp_->path() / "data" / "jobs" / id / "solver.log");
  const std::string text((std::istreambuf_iterator<char>(log)), {});
  EXPECT_NE(text.find("stopped while filling and settling the bed"), std::string::npos) << text;
}

// The cancel arrives as soon as the job is RUNNING, which is often before the solver child has
// exec'd. It used to inherit the server's Asio SIGTERM handler there and shut the server down (the
// "connection reset by peer" this test saw under load): the server must keep serving and the job end
// CANCELLED, whether the solver checkpointed or died of the SIGTERM before it installed its handler.
TEST_F(EndToEnd, CancelRunningJobCheckpointsAndEndsCancelled) {
  auto server = start(1);
  const std::string db = upload(*server);
  try {
    const std::string id = submit(*server, sprayJob(db, 1000.0, 3));
    ASSERT_EQ(pollJob(*server, id, [](const nlohmann::json& j) { return j.at("state") == "RUNNING"; })
                  .at("state"),
              "RUNNING");
    const auto r = server->post("/v1/jobs/" + id + ":cancel", "");
    EXPECT_EQ(r.status, 202) << r.body;
    EXPECT_EQ(r.json().at("state"), "CANCELLING");
    const auto done = pollJob(*server, id, isFinal);
    EXPECT_EQ(done.at("state"), "CANCELLED") << done.dump(2);

    // A job cancelled once its solver reports progress checkpoints first.
    const std::string late = submit(*server, sprayJob(db, 1000.0, 4));
    const auto running = pollJob(*server, late, [](const nlohmann::json& j) {
      return j.at("state") == "RUNNING" && j.at("progress").at("fraction").get<double>() > 0;
    });
    ASSERT_EQ(running.at("state"), "RUNNING") << running.dump(2);
    EXPECT_EQ(server->post("/v1/jobs/" + late + ":cancel", "").status, 202);
    const auto cancelled = pollJob(*server, late, isFinal);
    EXPECT_EQ(cancelled.at("state"), "CANCELLED") << cancelled.dump(2);
    const auto events = server->get("/v1/jobs/" + late + "/events").json().at("events");
    ASSERT_FALSE(events.empty());
    EXPECT_EQ(events.back().at("reason"), "the solver checkpointed and stopped") << events.dump(2);
    EXPECT_TRUE(std::filesystem::exists(tmp_->path() / "data" / "jobs" / late / "checkpoint.h5"));

    EXPECT_EQ(server->get("/v1/health").status, 200);
    EXPECT_EQ(server->stderrText().find("stopping"), std::string::npos) << server->stderrText();
  } catch (const std::exception& e) {
    FAIL() << e.what() << "; server alive: " << server->alive() << "; stderr:\n" << server->stderrText();
  }
}

/// Overwrites one value of a dataset of an HDF5 file (a damaged database for the upload tests).
void poke(const std::filesystem::path& path, const char* dataset, hsize_t rank, double value) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t set = H5Dopen2(file, dataset, H5P_DEFAULT);
  const hid_t space = H5Dget_space(set);
  std::vector<hsize_t> start(rank, 0), count(rank, 1);
  start[0] = 5;  // frame 5
  H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  const hid_t one = H5Screate_simple(1, count.data(), nullptr);
  H5Dwrite(set, H5T_NATIVE_DOUBLE, one, space, H5P_DEFAULT, &value);
  H5Sclose(one);
  H5Sclose(space);
  H5Dclose(set);
  H5Fclose(file);
}

// Uploads are validated before they are kept: each refusal names what is wrong (the dataset, the
// frame), the client exits 2 with the server's explanation, no partial file stays behind, and the
// server keeps serving. The good database is then accepted.
TEST_F(EndToEnd, InvalidUploadsAreRefusedNamingTheDatasetAndNothingIsKept) {
  auto server = start(0);
  const auto dir = tmp_->path();
  const auto databases = dir / "data" / "databases";
  const auto refused = [&](const std::filesystem::path& file, int status, const std::string& says) {
    const auto r = client(*server, {"upload", file.string()});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("HTTP " + std::to_string(status)), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("incoming"), std::string::npos) << r.err;  // no server paths
    EXPECT_TRUE(std::filesystem::is_empty(databases / "incoming"));
    EXPECT_EQ(server->get("/v1/health").status, 200);
  };
  std::ofstream(dir / "not.h5") << "this is not HDF5";
  refused(dir / "not.h5", 422, "not an HDF5 file");
  std::ofstream(dir / "empty.h5").close();
  refused(dir / "empty.h5", 400, "Empty upload");

  std::filesystem::copy_file(dir / "db.h5", dir / "missing.h5");
  const hid_t file = H5Fopen((dir / "missing.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(H5Ldelete(file, "/frames/u_g", H5P_DEFAULT), 0);
  H5Fclose(file);
  refused(dir / "missing.h5", 422, "/frames/u_g");

  std::filesystem::copy_file(dir / "db.h5", dir / "nan.h5");
  poke(dir / "nan.h5", "/frames/u_p", 5, std::nan(""));
  refused(dir / "nan.h5", 422, "frame 5");

  EXPECT_EQ(upload(*server).size(), 32u);
  int kept = 0;
  for (const auto& entry : std::filesystem::directory_iterator(databases)) kept += entry.is_regular_file();
  EXPECT_EQ(kept, 1);

  // An upload over --max-upload-bytes is 413 before its body is read.
  ServerProcess small(dir / "small", "e2e-token", {"--workers", "0", "--max-upload-bytes", "4096"});
  const auto r = client(small, {"upload", (dir / "db.h5").string()});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("HTTP 413"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("4096"), std::string::npos) << r.err;
  const auto smallIncoming = dir / "small" / "databases" / "incoming";
  EXPECT_TRUE(!std::filesystem::exists(smallIncoming) || std::filesystem::is_empty(smallIncoming));
  EXPECT_EQ(small.get("/v1/health").status, 200);
}

/// The first frame count of a database file's /frames/alpha_p ([N][nz][ny][nx]); -1 if unreadable.
long frameCount(const std::filesystem::path& path) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) return -1;
  long frames = -1;
  const hid_t set = H5Dopen2(file, "/frames/alpha_p", H5P_DEFAULT);
  if (set >= 0) {
    const hid_t space = H5Dget_space(set);
    hsize_t dims[4] = {0, 0, 0, 0};
    if (H5Sget_simple_extent_ndims(space) == 4 && H5Sget_simple_extent_dims(space, dims, nullptr) == 4)
      frames = long(dims[0]);
    H5Sclose(space);
    H5Dclose(set);
  }
  H5Fclose(file);
  return frames;
}

// The whole chain on the server: a small database job (the built-in DEM of a box, no gas, so it takes
// seconds) and a spray job submitted at once on the database job's id. The spray job waits for the
// database, runs on its frames, and its coverage downloads equal its result.h5.
TEST_F(EndToEnd, DatabaseJobThenSprayJobOnItsId) {
  auto server = start(1);
  nlohmann::json scene = nlohmann::json::parse(R"({
    "name": "e2e-database",
    "apparatus": {"type": "box", "size": [0.04, 0.1, 0.02]},
    "grid": {"cell_size": 0.005},
    "gas": {},
    "particles": {"diameter": 0.003, "density": 1040.0},
    "process": {"bed_mass": 0.005},
    "spray": {"nozzle_position": [0.0, 0.002, 0.01], "nozzle_diameter": 0.002, "parcels_per_s": 2000,
              "spray_zone": {"apex": [0.0, 0.0, 0.01], "half_angle_deg": 30, "y_min": 0.004, "y_max": 0.03}},
    "dem": {"time_step": 2e-5, "coupling_interval": 5, "settle_time": 0.1, "ramp_time": 0.0, "warmup": 0.01,
            "sample_rate": 200, "probe_rate": 1000, "sample_duration": 0.1, "reference_duration": 0.02},
    "rcfd": {"tracers": 200},
    "effects": ["rolling_friction"],
    "outputs": {"svg": false}
  })");
  const std::string db = submit(*server, {{"kind", "database"}, {"scene", scene}, {"seed", 3}});
  nlohmann::json sprayScene = scene;
  sprayScene["effects"] = {"transport", "walls", "tracer_volume_fraction", "spray", "deposition", "coverage"};
  nlohmann::json sprayOnDb = sprayJob(db, 0.25);
  sprayOnDb["scene"] = sprayScene;
  const std::string spray = submit(*server, sprayOnDb);

  const auto job = pollJob(*server, spray, isFinal, std::chrono::seconds(180));
  ASSERT_EQ(job.at("state"), "SUCCEEDED") << job.dump(2) << server->stderrText();
  const auto database = server->get("/v1/jobs/" + db).json();
  EXPECT_EQ(database.at("state"), "SUCCEEDED") << database.dump(2);
  EXPECT_EQ(database.at("kind"), "database");

  const auto dir = tmp_->path();
  ASSERT_EQ(client(*server, {"download", db, "database.h5", "-o", (dir / "d.h5").string()}).code, 0);
  EXPECT_EQ(frameCount(dir / "d.h5"), 20);  // 0.1 s at 200 Hz
  const auto dbSummary = nlohmann::json::parse(client(*server, {"result", db}).out);
  EXPECT_EQ(dbSummary.at("frames"), 20);
  EXPECT_GT(dbSummary.at("particles").get<long>(), 0);

  ASSERT_EQ(client(*server, {"coverage", spray, "--format", "csv", "-o", (dir / "c.csv").string()}).code, 0);
  ASSERT_EQ(client(*server, {"download", spray, "result.h5", "-o", (dir / "r.h5").string()}).code, 0);
  const Histogram reference = readH5(dir / "r.h5", "/coverage/histogram_edges", "/coverage/histogram_counts");
  ASSERT_FALSE(reference.counts.empty());
  const Histogram csv = readCsv(dir / "c.csv");
  EXPECT_EQ(csv.edges, reference.edges);
  EXPECT_EQ(csv.counts, reference.counts);
  double tracers = 0;
  for (double c : reference.counts) tracers += c;
  EXPECT_EQ(tracers, double(kTracers));
}

}  // namespace
