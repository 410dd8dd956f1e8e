// The REST API against a real rcfd-server on loopback: auth, every kind of bad request with its 4xx
// and problem+json body, idempotent submit, pagination, cancel, metrics. Workers are 0, so jobs stay
// QUEUED and no solver runs.

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

#include "ServerFixture.hpp"
#include "scene/SchemaValidator.hpp"

using namespace rcfd::test;
namespace http = boost::beast::http;

namespace {

class Api : public ::testing::Test {
 protected:
  void SetUp() override {
    data_ = std::make_unique<TempDir>();
    server_ = std::make_unique<ServerProcess>(data_->path() / "data", "test-token-123");
  }
  /// After any bad request the server must still answer.
  void expectStillServing() {
    const auto health = httpRequest(server_->port(), http::verb::get, "/v1/health");
    EXPECT_EQ(health.status, 200);
  }
  static void expectProblem(const Reply& r, int status) {
    EXPECT_EQ(r.status, status) << r.body;
    EXPECT_EQ(r.header("content-type"), "application/problem+json");
    const auto p = r.json();
    EXPECT_EQ(p.at("status").get<int>(), status);
    EXPECT_FALSE(p.at("title").get<std::string>().empty());
    EXPECT_TRUE(p.contains("type"));
    EXPECT_TRUE(p.contains("detail"));
    EXPECT_TRUE(p.contains("instance"));
  }
  std::unique_ptr<TempDir> data_;
  std::unique_ptr<ServerProcess> server_;
};

TEST_F(Api, PrintsListeningLineAndServesHealthWithoutToken) {
  EXPECT_EQ(server_->firstLine(), server_->url().insert(0, "listening on "));
  const auto r = httpRequest(server_->port(), http::verb::get, "/v1/health");
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.json().at("status"), "ok");
}

TEST_F(Api, MissingOrWrongTokenIs401WithChallenge) {
  const auto missing = httpRequest(server_->port(), http::verb::get, "/v1/jobs");
  expectProblem(missing, 401);
  EXPECT_EQ(missing.header("www-authenticate"), "Bearer realm=\"rcfd\"");
  const auto wrong = httpRequest(server_->port(), http::verb::get, "/v1/jobs", "test-token-124");
  expectProblem(wrong, 401);
  const auto metrics = httpRequest(server_->port(), http::verb::get, "/metrics", "nope");
  expectProblem(metrics, 401);
  EXPECT_EQ(server_->get("/v1/jobs").status, 200);
  expectStillServing();
}

TEST_F(Api, InvalidJsonIs400) {
  const auto r = server_->post("/v1/jobs", "{\"kind\": \"spray\",");
  expectProblem(r, 400);
  EXPECT_NE(r.json().at("detail").get<std::string>().find("JSON"), std::string::npos);
  expectStillServing();
}

TEST_F(Api, HealthWithATrailingSlashNeedsNoTokenEither) {
  const auto r = httpRequest(server_->port(), http::verb::get, "/v1/health/");
  EXPECT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(r.json().at("status"), "ok");
}

TEST_F(Api, AJobThatIsNotSentAsJsonIs415) {
  for (const std::string type : {"application/x-www-form-urlencoded", "text/plain"}) {
    const auto r = server_->post("/v1/jobs", databaseJob().dump(), {{"Content-Type", type}});
    expectProblem(r, 415);
    EXPECT_NE(r.json().at("detail").get<std::string>().find(type), std::string::npos) << r.body;
  }
  const auto ok = server_->post("/v1/jobs", databaseJob().dump(), {{"Content-Type", "application/json; charset=utf-8"}});
  EXPECT_EQ(ok.status, 202) << ok.body;
}

TEST_F(Api, ANumberBeyondDoubleRangeIs400) {
  auto job = databaseJob();
  job.erase("seed");
  std::string body = job.dump();
  body.insert(body.find('{') + 1, "\"seed\": 1e400, ");
  const auto r = server_->post("/v1/jobs", body);
  expectProblem(r, 400);
  EXPECT_NE(r.json().at("detail").get<std::string>().find("1e400"), std::string::npos) << r.body;
  expectStillServing();
}

TEST_F(Api, ADatabaseJobWhoseBedCannotFitIsRefusedAtSubmit) {
  auto job = databaseJob();
  job["scene"]["process"]["bed_mass"] = 1e12;
  const auto r = server_->post("/v1/jobs", job.dump());
  expectProblem(r, 422);
  EXPECT_EQ(r.json().at("errors").at(0).at("pointer"), "/scene/process/bed_mass") << r.body;
  EXPECT_TRUE(server_->get("/v1/jobs").json().at("jobs").empty());
}

TEST_F(Api, ADatabaseJobWhoseScheduleTheSolverWouldRefuseIsRefusedAtSubmit) {
  auto job = databaseJob();
  job["scene"]["dem"]["sample_duration"] = 0.0123;  // 2.46 frames at 200 Hz
  const auto r = server_->post("/v1/jobs", job.dump());
  expectProblem(r, 422);
  EXPECT_EQ(r.json().at("errors").at(0).at("pointer"), "/scene/dem/sample_duration") << r.body;
  EXPECT_TRUE(server_->get("/v1/jobs").json().at("jobs").empty());
}

TEST_F(Api, ACalibrationJobThatWouldStopAtItsStartIsRefusedAtSubmit) {
  nlohmann::json job = {{"kind", "calibration"}, {"scene", quickScene()}, {"database", "any"},
                        {"duration", 2.0}, {"discard", 3.0}};
  const auto r = server_->post("/v1/jobs", job.dump());
  expectProblem(r, 422);
  EXPECT_EQ(r.json().at("errors").at(0).at("pointer"), "/discard") << r.body;
  EXPECT_TRUE(server_->get("/v1/jobs").json().at("jobs").empty());
}

TEST_F(Api, OnlyAFailedOrCancelledJobIsRetriedAndItIsQueuedAgain) {
  const auto submitted = server_->post("/v1/jobs", databaseJob(7).dump());
  ASSERT_EQ(submitted.status, 202) << submitted.body;
  const std::string id = submitted.json().at("id");
  EXPECT_EQ(submitted.json().at("links").at("retry"), "/v1/jobs/" + id + ":retry");
  expectProblem(server_->post("/v1/jobs/" + id + ":retry", ""), 409);  // QUEUED
  ASSERT_EQ(server_->post("/v1/jobs/" + id + ":cancel", "").status, 200);
  const auto retried = server_->post("/v1/jobs/" + id + ":retry", "");
  ASSERT_EQ(retried.status, 200) << retried.body;
  EXPECT_EQ(retried.json().at("state"), "QUEUED");
  EXPECT_TRUE(retried.json().at("finished_at").is_null()) << retried.body;
  const auto events = server_->get("/v1/jobs/" + id + "/events").json().at("events");
  EXPECT_EQ(events.back().at("from"), "CANCELLED");
  EXPECT_NE(events.back().at("reason").get<std::string>().find("no checkpoint"), std::string::npos) << events.dump();
  expectProblem(server_->post("/v1/jobs/00000000000000000000000000000000:retry", ""), 404);
  expectProblem(server_->get("/v1/jobs/" + id + ":retry"), 405);
}

TEST_F(Api, SchemaViolationIs422WithPointer) {
  auto job = databaseJob();
  job["kind"] = "teleport";
  const auto r = server_->post("/v1/jobs", job.dump());
  expectProblem(r, 422);
  bool found = false;
  const auto body = r.json();
  for (const auto& e : body.at("errors")) found = found || e.at("pointer") == "/kind";
  EXPECT_TRUE(found) << r.body;

  auto unknown = databaseJob();
  unknown["colour"] = "blue";  // unknown keys are errors (docs/contracts.md)
  const auto r2 = server_->post("/v1/jobs", unknown.dump());
  expectProblem(r2, 422);
  expectStillServing();
}

TEST_F(Api, SceneFileIsRefusedByTheServer) {
  auto job = databaseJob();
  job.erase("scene");
  job["scene_file"] = "/etc/passwd";
  const auto r = server_->post("/v1/jobs", job.dump());
  expectProblem(r, 422);
  EXPECT_EQ(r.json().at("errors").at(0).at("pointer"), "/scene_file");
}

namespace {

/// Pointers of the string properties whose name says they hold a file or directory, found by walking
/// the schema the way SchemaValidator::filePathPointers() does, but by name instead of annotation.
void pathLikeProperties(const nlohmann::json& root, const nlohmann::json& node, const std::string& pointer,
                        std::vector<std::string>& out, int depth = 0) {
  if (!node.is_object() || depth > 64) return;
  if (const auto ref = node.find("$ref"); ref != node.end() && ref->get<std::string>().rfind("#/", 0) == 0)
    pathLikeProperties(root, root.at(nlohmann::json::json_pointer(ref->get<std::string>().substr(1))), pointer, out, depth + 1);
  for (const char* branch : {"oneOf", "anyOf", "allOf"})
    if (node.contains(branch))
      for (const auto& sub : node.at(branch)) pathLikeProperties(root, sub, pointer, out, depth + 1);
  if (!node.contains("properties")) return;
  for (const auto& [name, sub] : node.at("properties").items()) {
    std::string lower = name;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    const bool named = lower.find("file") != std::string::npos || lower.find("dir") != std::string::npos ||
                       lower == "path" || lower.find("_path") != std::string::npos;
    if (named && sub.value("type", "") == "string" && std::find(out.begin(), out.end(), pointer + "/" + name) == out.end())
      out.push_back(pointer + "/" + name);
    pathLikeProperties(root, sub, pointer + "/" + name, out, depth + 1);
  }
}

}  // namespace

TEST_F(Api, NoFileTheSolverWouldOpenIsTakenFromAJob) {
  // Every string property named like a file or directory is marked x-file-path in its schema (so one
  // added later is caught here), and the server refuses each one set in a job's scene, inline or
  // patched: the solver would open it as the server's user.
  std::vector<std::string> named, marked;
  for (const std::string schema : {"scene", "job"}) {
    const auto& v = rcfd::SchemaValidator::get(schema);
    std::vector<std::string> n;
    pathLikeProperties(v.schema(), v.schema(), "", n);
    for (const auto& p : n) named.push_back(schema + ":" + p);
    for (const auto& p : v.filePathPointers()) marked.push_back(schema + ":" + p);
  }
  std::sort(named.begin(), named.end());
  std::sort(marked.begin(), marked.end());
  EXPECT_EQ(named, marked);
  ASSERT_NE(std::find(marked.begin(), marked.end(), "scene:/rcfd/path/file"), marked.end());

  for (const auto& pointer : rcfd::SchemaValidator::get("scene").filePathPointers()) {
    const nlohmann::json::json_pointer at(pointer);
    auto inlineJob = databaseJob();
    inlineJob["scene"][at] = "/etc/passwd";
    auto patched = databaseJob();
    patched["scene_patch"] = nlohmann::json::object();
    patched["scene_patch"][at] = "/etc/passwd";
    for (const auto& job : {inlineJob, patched}) {
      const auto r = server_->post("/v1/jobs", job.dump());
      expectProblem(r, 422);
      EXPECT_EQ(r.json().at("errors").at(0).at("pointer"), "/scene" + pointer) << r.body;
      EXPECT_EQ(r.body.find("root:"), std::string::npos) << r.body;  // nothing of the file in the reply
    }
  }
  EXPECT_TRUE(server_->get("/v1/jobs").json().at("jobs").empty());
  expectStillServing();
}

TEST_F(Api, UnknownOrFailedDatabaseReferenceIs422) {
  nlohmann::json spray = {{"kind", "spray"}, {"scene", quickScene()},
                          {"database", "0123456789abcdef0123456789abcdef"}, {"duration", 1.0}};
  const auto r = server_->post("/v1/jobs", spray.dump());
  expectProblem(r, 422);
  bool found = false;
  const auto body = r.json();
  for (const auto& e : body.at("errors")) found = found || e.at("pointer") == "/database";
  EXPECT_TRUE(found) << r.body;

  // A cancelled database job cannot serve as a database either.
  const auto db = server_->post("/v1/jobs", databaseJob(7).dump()).json();
  ASSERT_EQ(server_->post("/v1/jobs/" + db.at("id").get<std::string>() + ":cancel", "").status, 200);
  spray["database"] = db.at("id");
  expectProblem(server_->post("/v1/jobs", spray.dump()), 422);
}

TEST_F(Api, SprayOnAQueuedDatabaseJobIsAcceptedAndWaits) {
  const std::string db = server_->post("/v1/jobs", databaseJob(9).dump()).json().at("id");
  const nlohmann::json spray = {{"kind", "spray"}, {"scene", quickScene()}, {"database", db},
                                {"duration", 1.0}};
  const auto r = server_->post("/v1/jobs", spray.dump());
  ASSERT_EQ(r.status, 202) << r.body;
  EXPECT_EQ(r.json().at("database"), db);
  EXPECT_EQ(r.json().at("state"), "QUEUED");
  // A spray job without a database is refused.
  auto none = spray;
  none.erase("database");
  expectProblem(server_->post("/v1/jobs", none.dump()), 422);
}

TEST_F(Api, OversizeBodyIs413) {
  const std::string big(2u << 20, ' ');  // 2 MiB of whitespace, over the 1 MiB JSON limit
  const auto r = server_->post("/v1/jobs", big);
  expectProblem(r, 413);
  expectStillServing();
}

TEST_F(Api, UnknownJobIs404) {
  const std::string id = "00000000000000000000000000000000";
  expectProblem(server_->get("/v1/jobs/" + id), 404);
  expectProblem(server_->get("/v1/jobs/" + id + "/result"), 404);
  expectProblem(server_->post("/v1/jobs/" + id + ":cancel", ""), 404);
  expectProblem(server_->get("/v1/nothing-here"), 404);
  expectStillServing();
}

TEST_F(Api, ArtifactPathsAreRefused) {
  const auto job = server_->post("/v1/jobs", databaseJob().dump()).json();
  const std::string base = "/v1/jobs/" + job.at("id").get<std::string>() + "/artifacts/";
  for (const std::string name : {"../../rcfd.sqlite", "..%2F..%2Frcfd.sqlite", "..", "token",
                                 "rcfd.sqlite", "%2e%2e%2ftoken", "x/../../token"}) {
    const auto r = server_->get(base + name);
    EXPECT_EQ(r.status, 400) << name;  // refused by name, before any file is looked at
    EXPECT_EQ(r.header("content-type"), "application/problem+json") << name;
    EXPECT_EQ(r.body.find("test-token-123"), std::string::npos);
  }
  // A valid name the job has not produced yet is 404.
  expectProblem(server_->get(base + "result.h5"), 404);
  expectStillServing();
}

TEST_F(Api, SubmitAnswers202WithLocationAndRetryAfter) {
  const auto r = server_->post("/v1/jobs", databaseJob().dump());
  ASSERT_EQ(r.status, 202) << r.body;
  const auto job = r.json();
  const std::string id = job.at("id");
  EXPECT_EQ(id.size(), 32u);
  EXPECT_EQ(r.header("location"), "/v1/jobs/" + id);
  EXPECT_FALSE(r.header("retry-after").empty());
  EXPECT_EQ(job.at("state"), "QUEUED");
  const auto got = server_->get("/v1/jobs/" + id).json();
  EXPECT_EQ(got.at("kind"), "database");
  EXPECT_EQ(got.at("state"), "QUEUED");
  // A result does not exist before the job succeeded.
  expectProblem(server_->get("/v1/jobs/" + id + "/result"), 409);
  expectProblem(server_->get("/v1/jobs/" + id + "/coverage?format=csv"), 409);
}

TEST_F(Api, IdempotencyKeyReturnsSameJobAndRefusesDifferentBody) {
  const std::map<std::string, std::string> key = {{"Idempotency-Key", "retry-42"}};
  const auto first = server_->post("/v1/jobs", databaseJob(1).dump(), key);
  const auto second = server_->post("/v1/jobs", databaseJob(1).dump(), key);
  ASSERT_EQ(first.status, 202);
  ASSERT_EQ(second.status, 202);
  EXPECT_EQ(first.json().at("id"), second.json().at("id"));
  EXPECT_EQ(first.header("idempotent-replayed"), "");
  EXPECT_EQ(second.header("idempotent-replayed"), "true");
  // The key matches the JSON document, not its spelling: reordered keys are the same body.
  const auto respelled = server_->post("/v1/jobs", databaseJob(1).dump(2), key);
  EXPECT_EQ(respelled.status, 202);
  EXPECT_EQ(respelled.json().at("id"), first.json().at("id"));
  const auto all = server_->get("/v1/jobs").json();
  EXPECT_EQ(all.at("jobs").size(), 1u);
  const auto different = server_->post("/v1/jobs", databaseJob(2).dump(), key);
  expectProblem(different, 422);
  EXPECT_EQ(server_->get("/v1/jobs").json().at("jobs").size(), 1u);
}

TEST_F(Api, PaginatesTwentyFiveJobsInPagesOfTen) {
  std::vector<std::string> submitted;
  for (int i = 0; i < 25; ++i) {
    const auto r = server_->post("/v1/jobs", databaseJob(i).dump());
    ASSERT_EQ(r.status, 202);
    submitted.push_back(r.json().at("id"));
  }
  std::vector<std::string> seen;
  std::string token;
  int pages = 0;
  for (;;) {
    const auto page =
        server_->get("/v1/jobs?page_size=10" + (token.empty() ? "" : "&page_token=" + token)).json();
    ++pages;
    for (const auto& j : page.at("jobs")) seen.push_back(j.at("id"));
    if (!page.contains("next_page_token")) {
      EXPECT_EQ(page.at("jobs").size(), 5u);
      break;
    }
    EXPECT_EQ(page.at("jobs").size(), 10u);
    token = page.at("next_page_token");
    ASSERT_LT(pages, 5);
  }
  EXPECT_EQ(pages, 3);
  EXPECT_EQ(seen, submitted);  // every job once, in submission order
  // A token used with other filters, or a forged one, is refused.
  expectProblem(server_->get("/v1/jobs?page_size=10&state=RUNNING&page_token=" + token), 400);
  expectProblem(server_->get("/v1/jobs?page_token=garbage!"), 400);
  // Well-formed but not issued by this server: {"after":1,"kind":"","state":""} unsigned, with a made-up
  // signature, and with the signature of a real token.
  const std::string payload = "eyJhZnRlciI6MSwia2luZCI6IiIsInN0YXRlIjoiIn0";
  const std::string signature = token.substr(token.find('.') + 1);
  for (const std::string& forged : {payload, payload + ".AAAA", payload + "." + signature})
    expectProblem(server_->get("/v1/jobs?page_size=10&page_token=" + forged), 400);
  // The signing key is kept in the data directory: a token outlives a restart of the server.
  const auto second = server_->get("/v1/jobs?page_size=10").json().at("next_page_token").get<std::string>();
  server_ = std::make_unique<ServerProcess>(data_->path() / "data", "test-token-123");
  const auto after = server_->get("/v1/jobs?page_size=10&page_token=" + second);
  ASSERT_EQ(after.status, 200) << after.body;
  EXPECT_EQ(after.json().at("jobs").at(0).at("id"), submitted[10]);
  expectProblem(server_->get("/v1/jobs?page_size=0"), 400);
  expectProblem(server_->get("/v1/jobs?state=DONE"), 400);
}

TEST_F(Api, FiltersByStateAndKind) {
  const auto a = server_->post("/v1/jobs", databaseJob(1).dump()).json();
  server_->post("/v1/jobs", databaseJob(2).dump());
  server_->post("/v1/jobs/" + a.at("id").get<std::string>() + ":cancel", "");
  const auto cancelled = server_->get("/v1/jobs?state=CANCELLED").json().at("jobs");
  ASSERT_EQ(cancelled.size(), 1u);
  EXPECT_EQ(cancelled[0].at("id"), a.at("id"));
  EXPECT_EQ(server_->get("/v1/jobs?state=QUEUED").json().at("jobs").size(), 1u);
  EXPECT_EQ(server_->get("/v1/jobs?kind=database").json().at("jobs").size(), 2u);
  EXPECT_EQ(server_->get("/v1/jobs?kind=spray").json().at("jobs").size(), 0u);
}

TEST_F(Api, CancelQueuedJobAtOnceAndRecordsEvents) {
  const std::string id = server_->post("/v1/jobs", databaseJob().dump()).json().at("id");
  // Polled twice while QUEUED (the second answer comes from the view cache) ...
  EXPECT_EQ(server_->get("/v1/jobs/" + id).json().at("state"), "QUEUED");
  EXPECT_EQ(server_->get("/v1/jobs/" + id).json().at("state"), "QUEUED");
  const auto r = server_->post("/v1/jobs/" + id + ":cancel", "");
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(r.json().at("state"), "CANCELLED");
  EXPECT_FALSE(r.json().at("finished_at").is_null());
  // ... and the next poll sees the change at once, in both views.
  const auto polled = server_->get("/v1/jobs/" + id).json();
  EXPECT_EQ(polled.at("state"), "CANCELLED");
  EXPECT_EQ(polled, r.json());
  EXPECT_EQ(server_->get("/v1/jobs/" + id + "?view=full").json().at("state"), "CANCELLED");
  // Cancelling a finished job is a conflict.
  expectProblem(server_->post("/v1/jobs/" + id + ":cancel", ""), 409);
  const auto events = server_->get("/v1/jobs/" + id + "/events").json().at("events");
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].at("to"), "QUEUED");
  EXPECT_EQ(events[1].at("from"), "QUEUED");
  EXPECT_EQ(events[1].at("to"), "CANCELLED");
}

TEST_F(Api, MetricsExposeJobGaugesAndLatencyHistogram) {
  server_->post("/v1/jobs", databaseJob(1).dump());
  server_->post("/v1/jobs", databaseJob(2).dump());
  const auto r = server_->get("/metrics");
  ASSERT_EQ(r.status, 200);
  EXPECT_NE(r.header("content-type").find("text/plain"), std::string::npos);
  EXPECT_NE(r.body.find("rcfd_jobs{state=\"QUEUED\"} 2"), std::string::npos) << r.body;
  EXPECT_NE(r.body.find("rcfd_jobs{state=\"SUCCEEDED\"} 0"), std::string::npos);
  EXPECT_NE(r.body.find("rcfd_queue_length 2"), std::string::npos);
  EXPECT_NE(r.body.find("rcfd_http_request_duration_seconds_bucket{le=\"+Inf\"}"), std::string::npos);
  EXPECT_NE(r.body.find("rcfd_http_requests_total{code=\"2xx\"}"), std::string::npos);

  // The histogram is consistent: buckets cumulative, +Inf = count; every answered request (the 2
  // submits, the /metrics above and one 404) counted by status class. A request is
  // counted once its response is written, which may be just after the client has read it: poll.
  expectProblem(server_->get("/v1/jobs/00000000000000000000000000000000"), 404);
  std::map<std::string, double> samples;
  std::vector<double> buckets;
  for (int attempt = 0; attempt < 50; ++attempt) {
    samples.clear();
    buckets.clear();
    std::istringstream lines(server_->get("/metrics").body);
    for (std::string line; std::getline(lines, line);) {
      if (line.empty() || line[0] == '#') continue;
      const auto space = line.rfind(' ');
      const double value = std::stod(line.substr(space + 1));
      samples[line.substr(0, space)] = value;
      if (line.rfind("rcfd_http_request_duration_seconds_bucket", 0) == 0) buckets.push_back(value);
    }
    if (samples["rcfd_http_requests_total{code=\"4xx\"}"] >= 1 &&
        samples["rcfd_http_requests_total{code=\"2xx\"}"] >= 3)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(buckets.size(), 13u);  // 12 bounds and +Inf
  EXPECT_TRUE(std::is_sorted(buckets.begin(), buckets.end()));
  const double count = samples.at("rcfd_http_request_duration_seconds_count");
  EXPECT_EQ(buckets.back(), count);
  EXPECT_EQ(samples.at("rcfd_http_requests_total{code=\"4xx\"}"), 1);
  EXPECT_GE(samples.at("rcfd_http_requests_total{code=\"2xx\"}"), 3);
  EXPECT_EQ(samples.at("rcfd_http_requests_total{code=\"5xx\"}"), 0);
  EXPECT_GE(count, 4);  // the polls of /metrics add to it
  EXPECT_GT(samples.at("rcfd_http_request_duration_seconds_sum"), 0);
  EXPECT_EQ(samples.at("rcfd_workers_busy"), 0);
}

TEST_F(Api, ServesEmbeddedSchemas) {
  const auto job = server_->get("/v1/schemas/job");
  ASSERT_EQ(job.status, 200);
  EXPECT_NO_THROW((void)job.json());
  EXPECT_EQ(server_->get("/v1/schemas/scene").status, 200);
  expectProblem(server_->get("/v1/schemas/nothing"), 404);
}

TEST_F(Api, WrongMethodIs405WithAllow) {
  const auto r = httpRequest(server_->port(), http::verb::delete_, "/v1/jobs", server_->token());
  expectProblem(r, 405);
  EXPECT_EQ(r.header("allow"), "GET, POST");
}

}  // namespace
