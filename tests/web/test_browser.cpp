// The web page (server/web/, docs/web.md) in a real browser: Debian's chromium, driven headless by
// playwright-core from node (tests/web/browser.test.mjs), against a real rcfd-server on loopback with one
// worker and a small analytic field database (tests/server/SmallDatabase.hpp). The browser steps assert
// what a person sees; this side checks what the server ended up with.
//
// node, chromium and tests/web/node_modules (npm ci, run by scripts/test.sh) are needed: without them the
// test fails in CI (CI=true; scripts/install-deps.sh installs them) and is skipped, saying why, when run
// by hand.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "../server/ServerFixture.hpp"
#include "../server/SmallDatabase.hpp"

using namespace rcfd::test;

namespace {

constexpr const char* kToken = "web-test-token-5d1c";
const std::filesystem::path kWebTests = sourceDir() / "tests" / "web";

/// `name` as the shell finds it on PATH, or empty.
std::string onPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  for (std::size_t start = 0; start <= dirs.size();) {
    const auto end = std::min(dirs.find(':', start), dirs.size());
    const auto candidate = std::filesystem::path(dirs.substr(start, end - start)) / name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return {};
}

std::string chromiumPath() {
  const char* set = std::getenv("RCFD_CHROMIUM");
  return set ? set : "/usr/bin/chromium";
}

/// What is missing to run the browser tests, or empty.
std::string missingTools() {
  std::string missing;
  if (onPath("node").empty()) missing += " node (apt-get install nodejs npm);";
  if (::access(chromiumPath().c_str(), X_OK) != 0) missing += " " + chromiumPath() + " (apt-get install chromium);";
  if (!std::filesystem::exists(kWebTests / "node_modules" / "playwright-core" / "package.json"))
    missing += " tests/web/node_modules/playwright-core (npm ci --prefix tests/web);";
  return missing;
}

struct NodeRun {
  int code = -1;
  std::string output;
};

/// Runs `node script` in tests/web with `env` added, its stdout and stderr together; killed after
/// `limit` seconds so that a hung browser fails the test instead of hanging the suite.
NodeRun runNode(const std::string& script, const std::vector<std::string>& env, unsigned limit,
                const std::filesystem::path& outputFile, const std::vector<std::string>& moreArgs = {}) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::alarm(limit);
    for (const auto& e : env) ::putenv(const_cast<char*>(e.c_str()));
    const int out = ::open(outputFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ::dup2(out, 1);
    ::dup2(out, 2);
    if (::chdir(kWebTests.c_str()) != 0) ::_exit(126);
    std::vector<std::string> args = {"node", script};
    args.insert(args.end(), moreArgs.begin(), moreArgs.end());
    execOrExit(args);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  NodeRun run;
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(outputFile);
  run.output.assign(std::istreambuf_iterator<char>(in), {});
  return run;
}

class WebBrowser : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string missing = missingTools(); !missing.empty()) {
      if (std::getenv("CI")) FAIL() << "the browser tests need:" << missing << " (scripts/install-deps.sh, scripts/test.sh)";
      GTEST_SKIP() << "browser tests skipped, missing:" << missing;
    }
    if (!std::filesystem::exists(binaryDir() / "rcfd-solve")) GTEST_SKIP() << "build rcfd-solve first";
    tmp_ = std::make_unique<TempDir>();
    std::filesystem::create_directories(tmp_->path() / "downloads");
  }
  std::unique_ptr<ServerProcess> start() const {
    // The solver at the server's niceness: ctest runs other tests beside this one.
    return std::make_unique<ServerProcess>(
        tmp_->path() / "data", kToken,
        std::vector<std::string>{"--workers", "1", "--solver", (binaryDir() / "rcfd-solve").string(), "--worker-nice",
                                 "0", "--cancel-grace", "10"});
  }
  std::unique_ptr<TempDir> tmp_;
};

}  // namespace

TEST_F(WebBrowser, SignInUploadSubmitWatchDownloadCancelValidateAndChainInChromium) {
  const auto database = tmp_->path() / "db.h5";
  writeSmallDatabase(quickScene(), database);
  const auto server = start();
  const auto downloads = tmp_->path() / "downloads";
  const NodeRun run = runNode("browser.test.mjs",
                              {"RCFD_WEB_URL=" + server->url(), std::string("RCFD_WEB_TOKEN=") + kToken,
                               "RCFD_WEB_DATABASE=" + database.string(), "RCFD_WEB_DOWNLOADS=" + downloads.string()},
                              300, tmp_->path() / "node.log");
  std::cout << run.output;
  ASSERT_EQ(run.code, 0) << "the browser steps failed (output above); server stderr:\n" << server->stderrText();

  // What the page did, as the server recorded it: one spray job done on the uploaded database, one
  // cancelled; the CSV the browser saved is the server's coverage.
  std::ifstream idFile(downloads / "spray-job-id");
  std::string sprayId;
  idFile >> sprayId;
  ASSERT_EQ(sprayId.size(), 32u);
  const auto jobs = server->get("/v1/jobs").json().at("jobs");
  ASSERT_EQ(jobs.size(), 4u) << jobs.dump(2);
  EXPECT_EQ(jobs[0].at("id"), sprayId);
  EXPECT_EQ(jobs[0].at("state"), "SUCCEEDED");
  EXPECT_EQ(jobs[1].at("state"), "CANCELLED");
  // The chain: a calibration, then a spray job with the D0 it selected.
  EXPECT_EQ(jobs[2].at("kind"), "calibration");
  EXPECT_EQ(jobs[2].at("state"), "SUCCEEDED");
  EXPECT_EQ(jobs[3].at("kind"), "spray");
  const auto selected = server->get("/v1/jobs/" + jobs[2].at("id").get<std::string>() + "/result").json().at("selected_d0");
  const auto chained = server->get("/v1/jobs/" + jobs[3].at("id").get<std::string>() + "?view=full").json();
  EXPECT_EQ(chained.at("request").at("scene").at("rcfd").at("d0"), selected);
  EXPECT_EQ(chained.at("request").at("database"), jobs[0].at("database"));
  const auto uploads = server->get("/v1/databases").json().at("databases");
  ASSERT_EQ(uploads.size(), 1u);
  EXPECT_EQ(jobs[0].at("database"), uploads[0].at("id"));
  const auto request = server->get("/v1/jobs/" + sprayId + "?view=full").json().at("request");
  EXPECT_EQ(request.at("scene").at("rcfd").at("tracers"), 200);
  EXPECT_EQ(request.at("duration"), 0.25);
  EXPECT_EQ(request.at("ensemble"), 2);
  std::ifstream csv(downloads / ("coverage-" + sprayId.substr(0, 8) + ".csv"));
  ASSERT_TRUE(csv) << "the downloaded CSV";
  const std::string saved(std::istreambuf_iterator<char>(csv), {});
  EXPECT_EQ(saved, server->get("/v1/jobs/" + sprayId + "/coverage?format=csv").body);
}

// The page's number formats and axis ticks (tests/web/format.test.mjs), in node without a browser.
TEST(WebFormats, TicksAndDurationsOfThePage) {
  if (onPath("node").empty()) {
    if (std::getenv("CI")) FAIL() << "node is missing (scripts/install-deps.sh)";
    GTEST_SKIP() << "node is missing";
  }
  TempDir tmp;
  const NodeRun run = runNode("--test", {}, 60, tmp.path() / "node.log", {"format.test.mjs"});
  EXPECT_EQ(run.code, 0) << run.output;
  EXPECT_NE(run.output.find("# pass 2"), std::string::npos) << run.output;
}

namespace {

nlohmann::json exampleScene(const std::string& name) {
  std::ifstream in(sourceDir() / "examples" / (name + ".json"));
  return nlohmann::json::parse(in);
}

}  // namespace

// The screenshots of docs/web.md and the README (docs/web-job.png, docs/web-compare.png): a spray job
// on the quick slice and one on the slice with draft plates, each on a small analytic database of its
// own scene, with the spray's mass rate raised 300-fold so that 2 s of spray coat the particles about
// as much as 10 minutes would (a chart with more than one bin filled, in seconds of run time). Run by
// scripts/web-screenshots.sh (RCFD_WEB_SCREENSHOTS=DIR); skipped otherwise.
TEST_F(WebBrowser, DocsScreenshots) {
  const char* out = std::getenv("RCFD_WEB_SCREENSHOTS");
  if (!out) GTEST_SKIP() << "set RCFD_WEB_SCREENSHOTS=DIR to write the page's screenshots (scripts/web-screenshots.sh)";
  const auto server = start();
  std::vector<std::string> ids;
  for (const std::string scene : {"quick", "quick-draft-plates"}) {
    const auto file = tmp_->path() / (scene + ".h5");
    writeSmallDatabase(exampleScene(scene), file);
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const Reply uploaded = server->post("/v1/databases", bytes, {{"Content-Type", "application/x-hdf5"}});
    ASSERT_EQ(uploaded.status, 201) << uploaded.body;
    nlohmann::json sprayScene = withTracers(exampleScene(scene), 4000);
    sprayScene["spray"]["mass_rate"] = sprayScene["spray"]["mass_rate"].get<double>() * 300.0;
    const nlohmann::json job = {{"kind", "spray"}, {"scene", sprayScene}, {"database", uploaded.json().at("id")},
                                {"duration", 2.0}, {"seed", 1}};
    const Reply submitted = server->post("/v1/jobs", job.dump());
    ASSERT_EQ(submitted.status, 202) << submitted.body;
    ids.push_back(submitted.json().at("id"));
  }
  for (const auto& id : ids) {
    std::string state;
    for (int i = 0; i < 1200 && state != "SUCCEEDED" && state != "FAILED"; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      state = server->get("/v1/jobs/" + id).json().at("state");
    }
    ASSERT_EQ(state, "SUCCEEDED") << server->get("/v1/jobs/" + id).body;
  }
  const NodeRun run = runNode("screenshots.mjs",
                              {"RCFD_WEB_URL=" + server->url(), std::string("RCFD_WEB_TOKEN=") + kToken,
                               "RCFD_WEB_JOBS=" + ids[0] + "," + ids[1],
                               "RCFD_WEB_SCREENSHOTS=" + std::filesystem::absolute(out).string()},
                              300, tmp_->path() / "node.log");
  std::cout << run.output;
  ASSERT_EQ(run.code, 0);
  for (const char* png : {"web-job.png", "web-compare.png"})
    EXPECT_GT(std::filesystem::file_size(std::filesystem::path(out) / png), 10000u) << png;
}
