// The `rcfd` client against a real server (workers 0: jobs stay QUEUED): submit with scene_file
// inlining and Idempotency-Key, jobs, status, cancel, wait across a server restart, and the messages
// and exit codes of errors.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "ClientRunner.hpp"
#include "ServerFixture.hpp"

using namespace rcfd::test;

namespace {

class Client : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = std::make_unique<TempDir>();
    server_ = std::make_unique<ServerProcess>(tmp_->path() / "data", "client-token");
    // A job file referring to its scene by path, as users write them.
    std::ofstream(tmp_->path() / "scene.json") << quickScene().dump(2);
    std::ofstream(tmp_->path() / "job.json")
        << nlohmann::json{{"kind", "database"}, {"scene_file", "scene.json"}, {"seed", 3}}.dump(2);
  }
  std::vector<std::string> env() const {
    return {"RCFD_SERVER=" + server_->url(), "RCFD_TOKEN=client-token"};
  }
  std::unique_ptr<TempDir> tmp_;
  std::unique_ptr<ServerProcess> server_;
};

TEST_F(Client, SubmitStatusJobsCancel) {
  const auto submit = runClient({"submit", (tmp_->path() / "job.json").string()}, env());
  ASSERT_EQ(submit.code, 0) << submit.err;
  const std::string id = firstLine(submit.out);
  ASSERT_EQ(id.size(), 32u) << submit.out;
  // The server received the scene inline.
  const auto stored = server_->get("/v1/jobs/" + id + "?view=full").json();
  EXPECT_EQ(stored.at("request").at("scene"), quickScene());
  EXPECT_FALSE(stored.at("request").contains("scene_file"));

  const auto status = runClient({"status", id}, env());
  EXPECT_EQ(status.code, 0) << status.err;
  EXPECT_NE(status.out.find("state:     QUEUED"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("owner:     admin"), std::string::npos) << status.out;  // the single token's user

  const auto jobs = runClient({"jobs", "--state", "QUEUED"}, env());
  EXPECT_EQ(jobs.code, 0);
  EXPECT_NE(jobs.out.find(id), std::string::npos);

  const auto cancel = runClient({"cancel", id}, env());
  EXPECT_EQ(cancel.code, 0) << cancel.err;
  EXPECT_NE(cancel.out.find("CANCELLED"), std::string::npos);
  EXPECT_EQ(server_->get("/v1/jobs/" + id).json().at("state"), "CANCELLED");
  const auto retried = runClient({"retry", id}, env());  // CANCELLED -> QUEUED
  EXPECT_EQ(retried.code, 0) << retried.err;
  EXPECT_NE(retried.out.find("QUEUED"), std::string::npos) << retried.out;
  ASSERT_EQ(runClient({"cancel", id}, env()).code, 0);
  EXPECT_EQ(runClient({"retry", "00000000000000000000000000000000"}, env()).code, 1);
  // A finished job's status shows when it finished.
  const auto finished = runClient({"status", id}, env());
  EXPECT_EQ(finished.code, 0) << finished.err;
  EXPECT_NE(finished.out.find("state:     CANCELLED"), std::string::npos) << finished.out;
  EXPECT_NE(finished.out.find("finished_at: "), std::string::npos) << finished.out;
  // Waiting on a cancelled job ends at once with exit 1 and says why.
  const auto wait = runClient({"wait", id}, env());
  EXPECT_EQ(wait.code, 1);
  EXPECT_NE(wait.err.find("CANCELLED"), std::string::npos);
}

TEST_F(Client, AServerThatStopsAnsweringTimesTheClientOutInsteadOfHangingIt) {
  ::kill(server_->pid(), SIGSTOP);  // connections still complete in the kernel; nothing answers
  const auto t0 = std::chrono::steady_clock::now();
  const auto jobs = runClient({"--timeout", "2", "jobs"}, env());
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ::kill(server_->pid(), SIGCONT);
  EXPECT_EQ(jobs.code, 1) << jobs.err;
  EXPECT_NE(jobs.err.find("no answer within 2 s"), std::string::npos) << jobs.err;
  EXPECT_LT(waited, 10.0);
  EXPECT_EQ(runClient({"jobs"}, env()).code, 0);  // answering again
}

TEST_F(Client, WaitKeepsWaitingAcrossAServerRestart) {
  const std::string id = firstLine(runClient({"submit", (tmp_->path() / "job.json").string()}, env()).out);
  ASSERT_EQ(id.size(), 32u);
  auto waiting = startClient({"wait", id, "--interval", "0.2", "--reconnect", "40"}, env());
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  const unsigned short port = server_->port();
  server_->stop(SIGTERM);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the client finds nobody listening
  server_ = std::make_unique<ServerProcess>(tmp_->path() / "data", "client-token", std::vector<std::string>{"--workers", "0"},
                                            0, "127.0.0.1:" + std::to_string(port));
  ASSERT_EQ(server_->post("/v1/jobs/" + id + ":cancel", "").status, 200);
  const auto waited = waiting.finish();
  // The job ended CANCELLED, which the wait reports (exit 1) having waited through the restart.
  EXPECT_EQ(waited.code, 1) << waited.err;
  EXPECT_NE(waited.err.find("unreachable"), std::string::npos) << waited.err;
  EXPECT_NE(waited.err.find("answers again"), std::string::npos) << waited.err;
  EXPECT_NE(waited.err.find("CANCELLED"), std::string::npos) << waited.err;
}

TEST_F(Client, WaitGivesUpAfterItsReconnectTimeSayingTheJobMayStillRun) {
  const std::string id = firstLine(runClient({"submit", (tmp_->path() / "job.json").string()}, env()).out);
  server_->stop(SIGTERM);
  const auto started = std::chrono::steady_clock::now();
  const auto waited = runClient({"wait", id, "--reconnect", "1"}, env());
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(10));
  EXPECT_EQ(waited.code, 1) << waited.err;
  EXPECT_NE(waited.err.find("gave up after 1 s"), std::string::npos) << waited.err;
  EXPECT_NE(waited.err.find("rcfd wait " + id), std::string::npos) << waited.err;
}

TEST_F(Client, FlagsOverrideEnvironmentAndIdempotencyKeyIsSent) {
  const std::vector<std::string> flags = {"--server", server_->url(), "--token", "client-token"};
  auto args = flags;
  args.insert(args.end(), {"submit", (tmp_->path() / "job.json").string(), "--idempotency-key", "k1"});
  const auto a = runClient(args, {"RCFD_SERVER=http://127.0.0.1:1", "RCFD_TOKEN=wrong"});
  const auto b = runClient(args, {"RCFD_SERVER=http://127.0.0.1:1", "RCFD_TOKEN=wrong"});
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_EQ(firstLine(a.out), firstLine(b.out));
  EXPECT_EQ(server_->get("/v1/jobs").json().at("jobs").size(), 1u);
}

TEST_F(Client, ErrorsAreExplainedWithExitCodes) {
  // Bad token: 401, exit 1, a hint about the token.
  auto bad = runClient({"jobs"}, {"RCFD_SERVER=" + server_->url(), "RCFD_TOKEN=nope"});
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("401"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("token"), std::string::npos);
  // Invalid job: 422, exit 2, the pointer printed.
  std::ofstream(tmp_->path() / "bad.json")
      << nlohmann::json{{"kind", "teleport"}, {"scene", quickScene()}}.dump();
  auto invalid = runClient({"submit", (tmp_->path() / "bad.json").string()}, env());
  EXPECT_EQ(invalid.code, 2);
  EXPECT_NE(invalid.err.find("/kind"), std::string::npos) << invalid.err;
  // Unknown job: 404, exit 1.
  auto missing = runClient({"status", "00000000000000000000000000000000"}, env());
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("404"), std::string::npos);
  // No server: exit 1 with a hint.
  auto down = runClient({"jobs"}, {"RCFD_SERVER=http://127.0.0.1:1", "RCFD_TOKEN=x"});
  EXPECT_EQ(down.code, 1);
  EXPECT_NE(down.err.find("cannot connect"), std::string::npos) << down.err;
  // A queued job has no result yet: 409, exit 1, saying which state it is in.
  const std::string queued = firstLine(runClient({"submit", (tmp_->path() / "job.json").string()}, env()).out);
  auto early = runClient({"result", queued}, env());
  EXPECT_EQ(early.code, 1);
  EXPECT_NE(early.err.find("HTTP 409"), std::string::npos) << early.err;
  EXPECT_NE(early.err.find("QUEUED"), std::string::npos) << early.err;
  // A path as artifact name: 400, exit 2, nothing written; a listed name not produced: 404, exit 1.
  const auto out = (tmp_->path() / "got").string();
  auto path = runClient({"download", queued, "../token", "-o", out}, env());
  EXPECT_EQ(path.code, 2);
  EXPECT_NE(path.err.find("HTTP 400"), std::string::npos) << path.err;
  EXPECT_NE(path.err.find("never"), std::string::npos) << path.err;  // "paths are never accepted"
  auto absent = runClient({"download", queued, "result.h5", "-o", out}, env());
  EXPECT_EQ(absent.code, 1);
  EXPECT_NE(absent.err.find("HTTP 404"), std::string::npos) << absent.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  // The same Idempotency-Key with another body: 422, exit 2, naming the job that holds the key.
  ASSERT_EQ(runClient({"submit", (tmp_->path() / "job.json").string(), "--idempotency-key", "k"}, env()).code, 0);
  std::ofstream(tmp_->path() / "other.json")
      << nlohmann::json{{"kind", "database"}, {"scene", quickScene()}, {"seed", 4}}.dump();
  auto reused = runClient({"submit", (tmp_->path() / "other.json").string(), "--idempotency-key", "k"}, env());
  EXPECT_EQ(reused.code, 2);
  EXPECT_NE(reused.err.find("HTTP 422 Idempotency-Key reused"), std::string::npos) << reused.err;
  // Usage error: exit 2.
  EXPECT_EQ(runClient({"coverage", "abc", "--format", "xml", "-o", "x"}, env()).code, 2);
  // Missing scene_file: exit 2 naming the pointer.
  std::ofstream(tmp_->path() / "noscene.json")
      << nlohmann::json{{"kind", "database"}, {"scene_file", "absent.json"}}.dump();
  auto noscene = runClient({"submit", (tmp_->path() / "noscene.json").string()}, env());
  EXPECT_EQ(noscene.code, 2);
  EXPECT_NE(noscene.err.find("/scene_file"), std::string::npos);
}

}  // namespace
