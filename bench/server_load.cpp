// rcfd-bench server: 200 keep-alive clients polling GET /v1/jobs/{id} of a real rcfd-server on loopback
// (started from beside rcfd-bench with a temporary data dir and one worker slot). A small field
// database (tests/server/SmallDatabase.hpp) is uploaded and a real spray job on examples/quick.json
// (20,000 tracers) runs in the worker while the clients poll its status: 30 s polling every 100 ms
// (the acceptance case), then 30 s back to back; then the job is cancelled and the finished
// job is polled again with no solver running (--quick: 3 s each). Reports p50/p99 latency, throughput
// and the server's own CPU time per request (from /proc: less sensitive to a shared machine than
// latency). Extra server arguments come from RCFD_BENCH_SERVER_ARGS (e.g. "--io-threads 1"), and
// RCFD_BENCH_SERVER_WRAPPER runs the server under a tool ("valgrind --tool=callgrind").
#include <signal.h>
#include <unistd.h>

#include <boost/beast/http.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include "../tests/server/ChildProcess.hpp"
#include "../tests/server/LoadGenerator.hpp"
#include "../tests/server/SmallDatabase.hpp"
#include "BenchRegistry.hpp"
#include "core/EmbeddedFiles.hpp"

namespace rcfd::bench {
namespace {

namespace http = boost::beast::http;

constexpr int kClients = 200;
constexpr double kSprayDuration = 3600.0;  // [s] simulated: far longer than the benchmark

/// One request on a fresh connection; returns the status and the body.
std::pair<int, std::string> request(unsigned short port, const std::string& token, http::verb method,
                                    const std::string& target, const std::string& body = {},
                                    const std::string& contentType = "application/json") {
  boost::asio::io_context ioc;
  boost::beast::tcp_stream stream(ioc);
  stream.connect({boost::asio::ip::make_address("127.0.0.1"), port});
  http::request<http::string_body> req{method, target, 11};
  req.set(http::field::host, "127.0.0.1");
  req.set(http::field::authorization, "Bearer " + token);
  if (method == http::verb::post) {
    req.set(http::field::content_type, contentType);
    req.body() = body;
  }
  req.prepare_payload();
  http::write(stream, req);
  boost::beast::flat_buffer buffer;
  http::response_parser<http::string_body> res;
  res.body_limit(64u << 20);
  http::read(stream, buffer, res);
  return {res.get().result_int(), res.get().body()};
}

nlohmann::json expect(const std::pair<int, std::string>& reply, int status, const char* what) {
  if (reply.first != status)
    throw std::runtime_error(std::string(what) + ": HTTP " + std::to_string(reply.first) + " " + reply.second);
  return nlohmann::json::parse(reply.second);
}

/// User + system CPU time of a process [s] (/proc/PID/stat fields 14 and 15).
double cpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  std::istringstream rest(text.substr(text.rfind(')') + 2));
  std::string field;
  double ticks = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i)
    if (i >= 14) ticks += std::stod(field);
  return ticks / double(::sysconf(_SC_CLK_TCK));
}

struct Phase {
  rcfd::test::LoadResult load;
  double serverCpuUsPerRequest = 0.0;
};

Phase measure(pid_t server, unsigned short port, const std::string& token, const std::string& target,
              std::chrono::seconds duration, std::chrono::milliseconds interval) {
  const double cpu0 = cpuSeconds(server);
  Phase p;
  p.load = rcfd::test::runStatusLoad(port, token, target, kClients, duration, 1, interval);
  p.serverCpuUsPerRequest = p.load.requests ? (cpuSeconds(server) - cpu0) * 1e6 / double(p.load.requests) : 0.0;
  return p;
}

nlohmann::json toJson(const Phase& p) {
  const auto& r = p.load;
  return {{"requests", r.requests}, {"errors", r.errors}, {"requests_per_s", r.requests / r.seconds},
          {"p50_ms", r.p50Ms}, {"p99_ms", r.p99Ms}, {"max_ms", r.maxMs},
          {"server_cpu_us_per_request", p.serverCpuUsPerRequest}};
}

void print(const char* what, const Phase& p) {
  const auto& r = p.load;
  std::printf("%s: %llu requests (%.0f req/s), p50 %.2f ms, p99 %.2f ms, max %.1f ms, errors %llu, "
              "server CPU %.1f us/request\n",
              what, static_cast<unsigned long long>(r.requests), r.requests / r.seconds, r.p50Ms, r.p99Ms,
              r.maxMs, static_cast<unsigned long long>(r.errors), p.serverCpuUsPerRequest);
  std::fflush(stdout);
}

std::vector<std::string> splitWords(const char* text) {
  std::vector<std::string> words;
  std::istringstream in(text ? text : "");
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

nlohmann::json run(const Options& options) {
  const auto self = std::filesystem::read_symlink("/proc/self/exe").parent_path();
  std::random_device rd;
  const auto dir = std::filesystem::temp_directory_path() / ("rcfd-bench-server-" + std::to_string(rd()));
  std::filesystem::create_directories(dir);
  const std::string token = "bench-token";
  std::ofstream(dir / "token") << token << "\n";
  const auto scene = nlohmann::json::parse(embeddedFiles().at("examples/quick.json"));
  rcfd::test::writeSmallDatabase(scene, dir / "db.h5");

  std::vector<std::string> args = {(self / "rcfd-server").string(), "--data-dir", (dir / "data").string(),
                                   "--listen", "127.0.0.1:0", "--token-file", (dir / "token").string(),
                                   "--workers", "1", "--solver", (self / "rcfd-solve").string()};
  const auto extra = splitWords(std::getenv("RCFD_BENCH_SERVER_ARGS"));
  args.insert(args.end(), extra.begin(), extra.end());
  const auto wrapper = splitWords(std::getenv("RCFD_BENCH_SERVER_WRAPPER"));  // e.g. valgrind
  args.insert(args.begin(), wrapper.begin(), wrapper.end());
  rcfd::test::ServerChild server(rcfd::test::ServerCommand(std::move(args)));
  if (!server.listening() || server.tls())  // the benchmark's requests are plain HTTP
    throw std::runtime_error("rcfd-server did not start (build rcfd-server and rcfd-solve beside rcfd-bench)");
  const auto port = server.port();
  const pid_t pid = server.pid();

  std::ifstream dbFile(dir / "db.h5", std::ios::binary);
  const std::string dbBytes((std::istreambuf_iterator<char>(dbFile)), {});
  const std::string db = expect(request(port, token, http::verb::post, "/v1/databases", dbBytes,
                                        "application/x-hdf5"),
                                201, "upload").at("id");
  const nlohmann::json job = {{"kind", "spray"}, {"scene", scene}, {"database", db},
                              {"duration", kSprayDuration}, {"seed", 1}, {"checkpoint_interval", 60.0}};
  const std::string id = expect(request(port, token, http::verb::post, "/v1/jobs", job.dump()), 202,
                                "submit").at("id");
  const std::string target = "/v1/jobs/" + id;
  // Poll until the solver reports progress: the recurrence set-up is done and it is stepping.
  nlohmann::json status;
  for (int i = 0; i < 1200; ++i) {
    status = expect(request(port, token, http::verb::get, target), 200, "status");
    if (status.at("state") != "QUEUED" && status.at("state") != "RUNNING") break;
    if (status.at("state") == "RUNNING" && status.at("progress").at("fraction").get<double>() > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (status.at("state") != "RUNNING")
    throw std::runtime_error("the spray job did not start: " + status.dump());

  // Simulated time the solver reached [s]: what the polls cost the job.
  const auto simTime = [&] {
    const auto now = expect(request(port, token, http::verb::get, target), 200, "status");
    const auto& t = now.at("progress").at("sim_time");
    return t.is_number() ? t.get<double>() : 0.0;
  };
  const auto seconds = std::chrono::seconds(options.quick ? 3 : 30);
  const double simStart = simTime();
  const auto polling = measure(pid, port, token, target, seconds, std::chrono::milliseconds(100));
  print("polling every 100 ms while the spray job runs", polling);
  const double simPolled = simTime() - simStart;
  std::printf("the solver advanced %.3f s of simulated time while polled\n", simPolled);
  const auto saturated = measure(pid, port, token, target, seconds, std::chrono::milliseconds(0));
  print("back to back while the spray job runs", saturated);
  const double simSaturated = simTime() - simStart - simPolled;
  std::printf("the solver advanced %.3f s of simulated time while the server was saturated\n", simSaturated);

  expect(request(port, token, http::verb::post, target + ":cancel"), 202, "cancel");
  for (int i = 0; i < 600 && status.at("state") != "CANCELLED"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    status = expect(request(port, token, http::verb::get, target), 200, "status");
  }
  const auto idle = measure(pid, port, token, target, seconds, std::chrono::milliseconds(100));
  print("polling every 100 ms, no job running (the cancelled job)", idle);

  server.stop(SIGTERM);
  std::filesystem::remove_all(dir);
  return {{"clients", kClients},
          {"seconds_each", seconds.count()},
          {"server_args", extra},
          {"p50_ms", polling.load.p50Ms},
          {"p99_ms", polling.load.p99Ms},
          {"solver_sim_s_while_polled", simPolled},
          {"solver_sim_s_while_saturated", simSaturated},
          {"polling_100ms_while_job_runs", toJson(polling)},
          {"back_to_back_while_job_runs", toJson(saturated)},
          {"polling_100ms_no_job_running", toJson(idle)}};
}

const bool registered = addBenchmark(
    "server", "rcfd-server: 200 clients polling job status on loopback while a spray job runs (p50/p99)", run);

}  // namespace
}  // namespace rcfd::bench
