#pragma once
/// \file HttpClient.hpp
/// A small synchronous HTTP/1.1 client (Boost.Beast) for the rcfd client: one connection per
/// request, bearer token, JSON bodies, streamed file uploads and downloads; http:// or https:// (the
/// server's certificate checked against the system's CAs or a given CA file, and its name against the
/// URL's host).

#include <chrono>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <memory>
#include <string>

namespace boost::asio::ssl {
class context;
}

namespace rcfd::client {

/// The server could not be reached or the exchange broke off.
class ConnectionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct HttpResponse {
  int status = 0;
  std::map<std::string, std::string> headers;  ///< lower-case names
  std::string body;                            ///< empty when streamed to a file
  std::string contentType() const;
  bool ok() const { return status >= 200 && status < 300; }
};

class HttpClient {
 public:
  /// `server` like "http://127.0.0.1:8080" or "https://rcfd.lab.example"; throws
  /// std::invalid_argument otherwise. Connecting, and each send or receive after it, fails with
  /// ConnectionError after `timeout`. For https, `caFile` (PEM) holds the certificates the server's
  /// is checked against; empty: the system's.
  HttpClient(const std::string& server, std::string token, std::chrono::seconds timeout = std::chrono::seconds(60),
             const std::string& caFile = {});
  ~HttpClient();

  HttpResponse get(const std::string& target);
  HttpResponse post(const std::string& target, const std::string& jsonBody,
                    const std::map<std::string, std::string>& headers = {});
  /// POSTs a file as application/octet-stream without loading it into memory.
  HttpResponse postFile(const std::string& target, const std::filesystem::path& file);
  /// GETs into a file (written only if the answer is 2xx; otherwise the body is returned).
  HttpResponse download(const std::string& target, const std::filesystem::path& file);

  const std::string& server() const { return server_; }

 private:
  /// Connects (and for https does the TLS handshake), then calls `exchange(stream)` with the
  /// connection's stream and closes it; every step within the timeout.
  template <class Exchange>
  void withConnection(Exchange&& exchange);
  /// Sends `request` on a new connection and reads the whole answer into memory: what get, post and
  /// postFile share (download streams its answer and has its own exchange).
  template <class Request>
  HttpResponse sendAndRead(Request& request);

  std::string server_, host_, port_, token_;
  std::chrono::seconds timeout_;
  std::shared_ptr<boost::asio::ssl::context> tls_;  ///< null for http://
};

}  // namespace rcfd::client
