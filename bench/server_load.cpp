// rcfd-bench server: 200 keep-alive clients polling GET /v1/jobs/{id} of a real rcfd-server on
// loopback (started from beside rcfd-bench with a temporary data dir and --workers 0), 30 s polling
// every 100 ms and 30 s back to back (--quick: 3 s each). Reports p50/p99 latency and throughput.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/beast/http.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>

#include "../tests/server/LoadGenerator.hpp"
#include "BenchRegistry.hpp"
#include "core/EmbeddedFiles.hpp"

namespace rcfd::bench {
namespace {

namespace http = boost::beast::http;

constexpr int kClients = 200;

/// POST /v1/jobs on a fresh connection; returns the job id.
std::string submit(unsigned short port, const std::string& token, const std::string& body) {
  boost::asio::io_context ioc;
  boost::beast::tcp_stream stream(ioc);
  stream.connect({boost::asio::ip::make_address("127.0.0.1"), port});
  http::request<http::string_body> req{http::verb::post, "/v1/jobs", 11};
  req.set(http::field::host, "127.0.0.1");
  req.set(http::field::authorization, "Bearer " + token);
  req.set(http::field::content_type, "application/json");
  req.body() = body;
  req.prepare_payload();
  http::write(stream, req);
  boost::beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(stream, buffer, res);
  if (res.result_int() != 202) throw std::runtime_error("submit failed: " + res.body());
  return nlohmann::json::parse(res.body()).at("id");
}

nlohmann::json toJson(const rcfd::test::LoadResult& r) {
  return {{"requests", r.requests}, {"errors", r.errors}, {"requests_per_s", r.requests / r.seconds},
          {"p50_ms", r.p50Ms}, {"p99_ms", r.p99Ms}, {"max_ms", r.maxMs}};
}

nlohmann::json run(const Options& options) {
  const auto self = std::filesystem::read_symlink("/proc/self/exe").parent_path();
  std::random_device rd;
  const auto dir = std::filesystem::temp_directory_path() / ("rcfd-bench-server-" + std::to_string(rd()));
  std::filesystem::create_directories(dir);
  const std::string token = "bench-token";
  std::ofstream(dir / "token") << token << "\n";
  int out[2];
  if (::pipe(out) != 0) throw std::runtime_error("pipe");
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(out[1], 1);
    const auto bin = (self / "rcfd-server").string(), data = (dir / "data").string(),
               tokenFile = (dir / "token").string();
    ::execl(bin.c_str(), bin.c_str(), "--data-dir", data.c_str(), "--listen", "127.0.0.1:0",
            "--token-file", tokenFile.c_str(), "--workers", "0", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(out[1]);
  std::string line;
  char c;
  while (::read(out[0], &c, 1) == 1 && c != '\n') line.push_back(c);
  ::close(out[0]);
  if (line.rfind("listening on http://", 0) != 0)
    throw std::runtime_error("rcfd-server did not start (build it beside rcfd-bench)");
  const auto port = static_cast<unsigned short>(std::stoi(line.substr(line.rfind(':') + 1)));

  const auto scene = nlohmann::json::parse(embeddedFiles().at("examples/quick.json"));
  const std::string id = submit(port, token, nlohmann::json{{"kind", "database"}, {"scene", scene}}.dump());
  const auto seconds = std::chrono::seconds(options.quick ? 3 : 30);
  const int threads = 1;  // the load generator's own threads; the server runs its default 2
  const auto polling = rcfd::test::runStatusLoad(port, token, "/v1/jobs/" + id, kClients, seconds,
                                                 threads, std::chrono::milliseconds(100));
  std::cout << "polling every 100 ms: " << polling.requests << " requests, p50 " << polling.p50Ms
            << " ms, p99 " << polling.p99Ms << " ms, errors " << polling.errors << "\n";
  const auto saturated = rcfd::test::runStatusLoad(port, token, "/v1/jobs/" + id, kClients, seconds, threads);
  std::cout << "back to back: " << saturated.requests / saturated.seconds << " req/s, p50 "
            << saturated.p50Ms << " ms, p99 " << saturated.p99Ms << " ms, errors " << saturated.errors
            << "\n";
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  std::filesystem::remove_all(dir);
  return {{"clients", kClients},
          {"seconds_each", seconds.count()},
          {"p50_ms", polling.p50Ms},
          {"p99_ms", polling.p99Ms},
          {"polling_100ms", toJson(polling)},
          {"back_to_back", toJson(saturated)}};
}

const bool registered = addBenchmark(
    "server", "rcfd-server: 200 clients polling job status on loopback (p50/p99 latency)", run);

}  // namespace
}  // namespace rcfd::bench
