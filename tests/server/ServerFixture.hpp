#pragma once
// Test helpers: start a real rcfd-server (from RCFD_BINARY_DIR) on 127.0.0.1:0 with a temporary data
// directory, and talk to it over real HTTP (Boost.Beast, one connection per request).

#include <unistd.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "ChildProcess.hpp"

namespace rcfd::test {

inline std::filesystem::path binaryDir() { return RCFD_BINARY_DIR; }
inline std::filesystem::path sourceDir() { return RCFD_SOURCE_DIR; }

/// A fresh directory under the system temp dir, removed by the destructor.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("rcfd-server-test-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

struct Reply {
  int status = 0;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string body;
  nlohmann::json json() const { return nlohmann::json::parse(body); }
  std::string header(const std::string& name) const {
    auto it = headers.find(name);
    return it == headers.end() ? std::string() : it->second;
  }
};

/// A response as a Reply: status, lower-case header names, body.
inline Reply replyOf(const boost::beast::http::response<boost::beast::http::string_body>& response) {
  Reply r;
  r.status = response.result_int();
  for (const auto& f : response) {
    std::string name(f.name_string());
    for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    r.headers[name] = std::string(f.value());
  }
  r.body = response.body();
  return r;
}

/// One HTTP exchange on a new connection.
inline Reply httpRequest(unsigned short port, boost::beast::http::verb method, const std::string& target,
                         const std::string& token = {}, const std::string& body = {},
                         const std::map<std::string, std::string>& headers = {}) {
  namespace http = boost::beast::http;
  boost::asio::io_context ioc;
  boost::beast::tcp_stream stream(ioc);
  stream.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
  http::request<http::string_body> req{method, target, 11};
  req.set(http::field::host, "127.0.0.1");
  if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
  for (const auto& [k, v] : headers) req.set(k, v);
  if (!body.empty() || method == http::verb::post) {
    if (!headers.count("Content-Type")) req.set(http::field::content_type, "application/json");
    req.body() = body;
  }
  req.prepare_payload();
  boost::beast::error_code writeEc, readEc;
  http::write(stream, req, writeEc);  // the server may answer early (413) and stop reading
  boost::beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(1ull << 30);
  http::read(stream, buffer, parser, readEc);
  if (readEc) throw std::runtime_error("http read failed: " + readEc.message());
  return replyOf(parser.get());
}

/// A running rcfd-server child process with its own data directory and token, and HTTP requests to it.
class ServerProcess : public ServerChild {
 public:
  /// fileLimit > 0: the server runs with at most that many open descriptors (RLIMIT_NOFILE). `listen`
  /// is its address (port 0: any free port; a restart passes the port of the server it replaces).
  /// An empty `token` passes no --token-file (for a server given --users-file in `extraArgs`); get()
  /// and post() then send no token. Throws std::runtime_error, with the server's stderr, when it does
  /// not start listening.
  ServerProcess(const std::filesystem::path& dataDir, std::string token,
                std::vector<std::string> extraArgs = {"--workers", "0"}, int fileLimit = 0,
                const std::string& listen = "127.0.0.1:0")
      : ServerChild(command(dataDir, token, std::move(extraArgs), fileLimit, listen)),
        stderrPath_(stderrPathOf(dataDir)),
        token_(std::move(token)) {
    if (!listening()) {
      // A server that refused to start has exited (one that printed something else is stopped): reap
      // it; its last words are in its stderr file.
      stop(SIGKILL);
      throw std::runtime_error("rcfd-server did not start: \"" + firstLine() + "\"; stderr: " + stderrText());
    }
  }

  const std::string& token() const { return token_; }
  std::string url() const { return (tls() ? "https" : "http") + std::string("://127.0.0.1:") + std::to_string(port()); }
  std::string stderrText() const {
    std::ifstream in(stderrPath_);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  Reply get(const std::string& target) const {
    return httpRequest(port(), boost::beast::http::verb::get, target, token_);
  }
  Reply post(const std::string& target, const std::string& body,
             const std::map<std::string, std::string>& headers = {}) const {
    return httpRequest(port(), boost::beast::http::verb::post, target, token_, body, headers);
  }

 private:
  /// The server's stderr, beside its data directory (so it outlives the server).
  static std::filesystem::path stderrPathOf(const std::filesystem::path& dataDir) {
    return dataDir.parent_path() / (dataDir.filename().string() + ".stderr");
  }
  /// The command line for the constructor's arguments; writes the token file it names.
  static ServerCommand command(const std::filesystem::path& dataDir, const std::string& token,
                               std::vector<std::string> extraArgs, int fileLimit, const std::string& listen) {
    std::vector<std::string> args = {(binaryDir() / "rcfd-server").string(), "--data-dir", dataDir.string(),
                                     "--listen", listen};
    if (!token.empty()) {
      const auto tokenFile = dataDir.parent_path() / (dataDir.filename().string() + ".token");
      std::ofstream(tokenFile) << token << "\n";
      args.insert(args.end(), {"--token-file", tokenFile.string()});
    }
    args.insert(args.end(), extraArgs.begin(), extraArgs.end());
    ServerCommand command(std::move(args));
    command.stderrFile = stderrPathOf(dataDir);
    command.fileLimit = fileLimit;
    return command;
  }

  std::filesystem::path stderrPath_;
  std::string token_;
};

/// The scene of examples/quick.json (a scene, or a job file holding one inline or via scene_file).
inline nlohmann::json quickScene() {
  const auto path = sourceDir() / "examples" / "quick.json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error("missing " + path.string());
  auto doc = nlohmann::json::parse(in);
  if (doc.contains("scene")) return doc["scene"];
  if (doc.contains("scene_file")) {
    std::ifstream s(path.parent_path() / doc["scene_file"].get<std::string>());
    return nlohmann::json::parse(s);
  }
  return doc;
}

/// A valid database job (seed varies the body, so each is a distinct request).
inline nlohmann::json databaseJob(int seed = 1) {
  return {{"kind", "database"}, {"scene", quickScene()}, {"seed", seed}};
}

}  // namespace rcfd::test
