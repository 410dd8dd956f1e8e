// What rcfd-server shows about itself and lets a client reach, on loopback: every problem names the
// request path as its `instance`, even a path that is not UTF-8; bad query parameters carry a JSON
// pointer like body violations; a client without the token learns nothing but 401; artifacts never
// follow a symlink; the data directory is owner-only; the served job.json holds no path of the
// server's machine.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <boost/asio/write.hpp>

#include "ServerFixture.hpp"
#include "SmallDatabase.hpp"

using namespace rcfd::test;
namespace http = boost::beast::http;

namespace {

constexpr const char* kToken = "exposure-token";

/// Sends `bytes` as they are (a request the Beast serializer would not write) and reads one response.
Reply rawExchange(unsigned short port, const std::string& bytes) {
  boost::asio::io_context ioc;
  boost::beast::tcp_stream stream(ioc);
  stream.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
  stream.expires_after(std::chrono::seconds(10));
  boost::beast::error_code writeEc, readEc;
  boost::asio::write(stream, boost::asio::buffer(bytes), writeEc);  // the server may answer early
  boost::beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  http::read(stream, buffer, parser, readEc);
  if (readEc) throw std::runtime_error("http read failed: " + readEc.message());
  return replyOf(parser.get());
}

/// The problem+json body of `r`, after checking that it is one with `status`.
nlohmann::json problemOf(const Reply& r, int status, const std::string& what) {
  EXPECT_EQ(r.status, status) << what << ": " << r.body;
  EXPECT_EQ(r.header("content-type"), "application/problem+json") << what;
  const auto body = nlohmann::json::parse(r.body, nullptr, false);
  EXPECT_TRUE(body.is_object()) << what << ": " << r.body;
  return body.is_object() ? body : nlohmann::json::object();
}

/// An executable standing in for rcfd-solve: writes result.h5 into its --out folder and fails (exit 3),
/// so a job runs, leaves its folder and ends FAILED within a second.
std::filesystem::path failingSolver(const std::filesystem::path& dir) {
  const auto path = dir / "failing-solver";
  {
    std::ofstream out(path);
    out << "#!/bin/sh\n# run JOB --out DIR --progress-json\necho written > \"$4/result.h5\"\nexit 3\n";
  }
  std::filesystem::permissions(path, std::filesystem::perms::owner_all);
  return path;
}

nlohmann::json waitUntilFinal(const ServerProcess& server, const std::string& id) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  nlohmann::json job;
  while (std::chrono::steady_clock::now() < deadline) {
    job = server.get("/v1/jobs/" + id).json();
    const std::string state = job.at("state");
    if (state == "SUCCEEDED" || state == "FAILED" || state == "CANCELLED") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return job;
}

/// The umask a test runs the server under, restored after it: the server's own umask must decide
/// the modes, not the one it inherits from whoever runs the tests.
class ScopedUmask {
 public:
  explicit ScopedUmask(mode_t mask) : previous_(::umask(mask)) {}
  ~ScopedUmask() { ::umask(previous_); }

 private:
  mode_t previous_;
};

unsigned modeOf(const std::filesystem::path& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return 07777;  // absent: matches no expected mode
  return st.st_mode & 07777;
}

std::string octal(unsigned mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", mode);
  return text;
}

}  // namespace

TEST(ServerExposure, EveryProblemNamesTheRequestPathAsItsInstance) {
  TempDir dir;
  ServerProcess server(dir.path() / "data", kToken, {"--workers", "0", "--max-body-bytes", "4096"});
  const std::string auth = std::string("Authorization: Bearer ") + kToken + "\r\n";
  const std::string postHead = "POST /v1/jobs?note=1 HTTP/1.1\r\nHost: a\r\nContent-Type: application/json\r\n";
  const std::vector<std::pair<std::string, std::string>> requests = {
      {"body over the limit by Content-Length", postHead + auth + "Content-Length: 5000\r\n\r\n"},
      {"chunked body over the limit",
       postHead + auth + "Transfer-Encoding: chunked\r\n\r\n1388\r\n" + std::string(5000, ' ') + "\r\n0\r\n\r\n"},
      {"malformed chunk", postHead + auth + "Transfer-Encoding: chunked\r\n\r\nzz\r\n\r\n"},
      {"header over 16 KiB", "GET /v1/jobs?note=1 HTTP/1.1\r\nHost: a\r\n" + auth + "X-Padding: " +
                                 std::string(20000, 'p') + "\r\n\r\n"},
      {"malformed header line", "GET /v1/jobs?note=1 HTTP/1.1\r\nHost: a\r\n" + auth + "no colon here\r\n\r\n"},
      {"malformed query", "GET /v1/jobs?state=%zz HTTP/1.1\r\nHost: a\r\n" + auth + "\r\n"},
      {"no token", "GET /v1/jobs?note=1 HTTP/1.1\r\nHost: a\r\n\r\n"},
  };
  for (const auto& [what, bytes] : requests) {
    const auto r = rawExchange(server.port(), bytes);
    EXPECT_GE(r.status, 400) << what;
    const auto problem = problemOf(r, r.status, what);
    EXPECT_EQ(problem.value("instance", ""), "/v1/jobs") << what << ": " << r.body;
  }
  const auto upload = rawExchange(server.port(), "POST /v1/databases?note=1 HTTP/1.1\r\nHost: a\r\n"
                                                 "Content-Length: 10\r\n\r\n0123456789");
  EXPECT_EQ(problemOf(upload, 401, "upload without a token").value("instance", ""), "/v1/databases");
  EXPECT_EQ(httpRequest(server.port(), http::verb::get, "/v1/health").status, 200);
}

TEST(ServerExposure, APathThatIsNotUtf8IsAnsweredWithAPercentEncodedInstanceAndTheServerLives) {
  TempDir dir;
  ServerProcess server(dir.path() / "data", kToken);
  const auto anonymous = rawExchange(server.port(), "GET /v1/jobs\xff HTTP/1.1\r\nHost: a\r\n\r\n");
  EXPECT_EQ(problemOf(anonymous, 401, "no token").value("instance", ""), "/v1/jobs%FF");
  const auto withToken = rawExchange(server.port(), std::string("GET /v1/jobs/\xfe\xff/result HTTP/1.1\r\n") +
                                                        "Host: a\r\nAuthorization: Bearer " + kToken + "\r\n\r\n");
  EXPECT_EQ(problemOf(withToken, 404, "with the token").value("instance", ""), "/v1/jobs/%FE%FF/result");
  EXPECT_TRUE(server.alive());
  EXPECT_EQ(httpRequest(server.port(), http::verb::get, "/v1/health").status, 200);
}

TEST(ServerExposure, ABadQueryParameterIs400WithAPointerUnderQueryAndWhatIsAllowed) {
  TempDir dir;
  ServerProcess server(dir.path() / "data", kToken);
  const std::string id = server.post("/v1/jobs", databaseJob().dump()).json().at("id");
  struct Case {
    std::string target, pointer, allowed;
  };
  const std::vector<Case> cases = {
      {"/v1/jobs?page_size=abc", "/query/page_size", "1 to 1000"},
      {"/v1/jobs?page_size=-1", "/query/page_size", "1 to 1000"},
      {"/v1/jobs?page_size=1001", "/query/page_size", "1 to 1000"},
      {"/v1/jobs?state=NOPE", "/query/state", "QUEUED, RUNNING, SUCCEEDED"},
      {"/v1/jobs?kind=teleport", "/query/kind", "database, calibration, spray"},
      {"/v1/jobs?page_token=forged", "/query/page_token", "previous page"},
      {"/v1/jobs/" + id + "?view=everything", "/query/view", "basic, full"},
  };
  for (const auto& c : cases) {
    const auto problem = problemOf(server.get(c.target), 400, c.target);
    EXPECT_EQ(problem.value("type", ""), "urn:rcfd:problem:invalid-parameter") << c.target;
    EXPECT_EQ(problem.value("instance", ""), c.target.substr(0, c.target.find('?'))) << c.target;
    ASSERT_TRUE(problem.contains("errors") && problem["errors"].is_array() && problem["errors"].size() == 1)
        << c.target << ": " << problem.dump();
    const auto& error = problem["errors"][0];
    EXPECT_EQ(error.value("pointer", ""), c.pointer) << c.target;
    EXPECT_NE(error.value("message", "").find(c.allowed), std::string::npos) << c.target << ": " << error.dump();
  }
  // A value that is not UTF-8 once decoded is still a 400 naming the parameter, never a 500.
  const auto binary = problemOf(server.get("/v1/jobs?state=%FF%FE"), 400, "state=%FF%FE");
  EXPECT_EQ(binary.at("errors").at(0).value("pointer", ""), "/query/state");
  EXPECT_EQ(server.get("/v1/jobs/" + id + "?view=full").status, 200);
  EXPECT_EQ(server.get("/v1/jobs/" + id + "?view=basic").status, 200);
}

TEST(ServerExposure, ARequestWithoutTheTokenIs401BeforeItsSizeOrSyntaxIsJudged) {
  TempDir dir;
  ServerProcess server(dir.path() / "data", kToken, {"--workers", "0", "--max-body-bytes", "4096"});
  const std::string postHead = "POST /v1/jobs HTTP/1.1\r\nHost: a\r\nContent-Type: application/json\r\n";
  const std::vector<std::pair<std::string, std::string>> requests = {
      {"Content-Length over the limit", postHead + "Content-Length: 100000000\r\n\r\n"},
      {"chunked body over the limit",
       postHead + "Transfer-Encoding: chunked\r\n\r\n1388\r\n" + std::string(5000, ' ') + "\r\n0\r\n\r\n"},
      {"malformed chunk", postHead + "Transfer-Encoding: chunked\r\n\r\nzz\r\n\r\n"},
      {"invalid JSON", postHead + "Content-Length: 5\r\n\r\n{\"a\":"},
      {"malformed query", "GET /v1/jobs?state=%zz HTTP/1.1\r\nHost: a\r\n\r\n"},
      {"upload over the limit", "POST /v1/databases HTTP/1.1\r\nHost: a\r\nContent-Length: 99999999999999\r\n\r\n"},
      {"wrong token, body over the limit",
       postHead + "Authorization: Bearer not-the-token\r\nContent-Length: 100000000\r\n\r\n"},
  };
  for (const auto& [what, bytes] : requests) {
    const auto r = rawExchange(server.port(), bytes);
    problemOf(r, 401, what);
    EXPECT_EQ(r.header("www-authenticate"), "Bearer realm=\"rcfd\"") << what;
  }
  // With the token the same requests are judged as before; health needs no token.
  EXPECT_EQ(rawExchange(server.port(), postHead + "Authorization: Bearer " + kToken +
                                           "\r\nContent-Length: 100000000\r\n\r\n").status, 413);
  EXPECT_EQ(httpRequest(server.port(), http::verb::get, "/v1/health").status, 200);
  EXPECT_EQ(httpRequest(server.port(), http::verb::get, "/v1/health/").status, 200);
}

TEST(ServerExposure, AnArtifactThatIsOrPassesThroughASymlinkIsNotServed) {
  TempDir dir;
  const auto data = dir.path() / "data";
  ServerProcess server(data, kToken);
  const auto outside = dir.path() / "outside";
  std::filesystem::create_directories(outside);
  {
    std::ofstream secret(outside / "solver.log");
    secret << "secret-outside-the-job\n";
  }
  // A link as the artifact itself ...
  const std::string linked = server.post("/v1/jobs", databaseJob(1).dump()).json().at("id");
  std::filesystem::create_directories(data / "jobs" / linked);
  std::filesystem::create_symlink(outside / "solver.log", data / "jobs" / linked / "solver.log");
  {
    std::ofstream real(data / "jobs" / linked / "summary.json");
    real << "{\"real\": true}\n";
  }
  // ... and a job folder that is a link to a folder elsewhere.
  const std::string folderLinked = server.post("/v1/jobs", databaseJob(2).dump()).json().at("id");
  std::filesystem::create_directory_symlink(outside, data / "jobs" / folderLinked);

  for (const auto& id : {linked, folderLinked}) {
    const auto r = server.get("/v1/jobs/" + id + "/artifacts/solver.log");
    problemOf(r, 404, "solver.log of " + id);
    EXPECT_EQ(r.body.find("secret-outside-the-job"), std::string::npos) << r.body;
  }
  // A regular file beside the link is still served.
  const auto real = server.get("/v1/jobs/" + linked + "/artifacts/summary.json");
  EXPECT_EQ(real.status, 200) << real.body;
  EXPECT_EQ(real.body, "{\"real\": true}\n");
}

TEST(ServerExposure, TheDataDirectoryAndWhatTheServerAndItsSolversCreateAreOwnerOnly) {
  const ScopedUmask permissive(022);
  TempDir dir;
  const auto data = dir.path() / "data";
  ServerProcess server(data, kToken, {"--workers", "1", "--solver", failingSolver(dir.path()).string()});
  const std::string id = server.post("/v1/jobs", databaseJob().dump()).json().at("id");
  ASSERT_EQ(waitUntilFinal(server, id).at("state"), "FAILED");
  for (const auto& folder : {data, data / "jobs", data / "databases", data / "jobs" / id})
    EXPECT_EQ(octal(modeOf(folder)), "0700") << folder;
  for (const auto& file : {data / "rcfd.sqlite", data / "jobs" / id / "job.json",
                           data / "jobs" / id / "solver.log", data / "jobs" / id / "result.h5"})
    EXPECT_EQ(octal(modeOf(file)), "0600") << file;
  EXPECT_EQ(server.stderrText().find("warning: data directory"), std::string::npos) << server.stderrText();
}

TEST(ServerExposure, AnExistingDataDirectoryOpenToOthersIsWarnedAboutAtStart) {
  TempDir dir;
  const auto data = dir.path() / "data";
  std::filesystem::create_directories(data);
  std::filesystem::permissions(data, std::filesystem::perms::owner_all | std::filesystem::perms::group_read |
                                         std::filesystem::perms::group_exec | std::filesystem::perms::others_read |
                                         std::filesystem::perms::others_exec);
  ServerProcess server(data, kToken);
  const std::string log = server.stderrText();
  EXPECT_NE(log.find("warning: data directory " + data.string() + " is accessible to others (mode 0755)"),
            std::string::npos)
      << log;
  EXPECT_EQ(server.get("/v1/jobs").status, 200);  // a warning, not a refusal
}

TEST(ServerExposure, TheServedJobFileShowsTheDatabaseIdAndNoPathOfTheServer) {
  TempDir dir;
  const auto data = dir.path() / "data";
  ServerProcess server(data, kToken, {"--workers", "1", "--solver", failingSolver(dir.path()).string()});
  const auto databaseFile = dir.path() / "db.h5";
  writeSmallDatabase(quickScene(), databaseFile);
  std::ifstream in(databaseFile, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const auto uploaded = server.post("/v1/databases", bytes, {{"Content-Type", "application/x-hdf5"}});
  ASSERT_EQ(uploaded.status, 201) << uploaded.body;
  const std::string database = uploaded.json().at("id");
  const nlohmann::json spray = {{"kind", "spray"}, {"scene", quickScene()}, {"database", database},
                                {"duration", 1.0}};
  const std::string id = server.post("/v1/jobs", spray.dump()).json().at("id");
  const auto job = waitUntilFinal(server, id);
  ASSERT_EQ(job.at("state"), "FAILED") << job.dump();

  const auto served = server.get("/v1/jobs/" + id + "/artifacts/job.json");
  ASSERT_EQ(served.status, 200) << served.body;
  EXPECT_EQ(served.header("content-type"), "application/json");
  EXPECT_EQ(served.body.find(dir.path().string()), std::string::npos) << served.body;
  const auto document = served.json();
  EXPECT_EQ(document.at("database"), database);
  EXPECT_EQ(document.at("kind"), "spray");
  // The solver itself got the database's path on this machine.
  std::ifstream onDisk(data / "jobs" / id / "job.json");
  EXPECT_EQ(nlohmann::json::parse(onDisk).at("database"), (data / "databases" / (database + ".h5")).string());
}
