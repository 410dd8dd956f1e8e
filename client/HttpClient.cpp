#include "HttpClient.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

namespace rcfd::client {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {
constexpr std::uint64_t kMaxResponseBody = 1ull << 40;  // downloads are streamed; no practical cap

template <class Fields>
void copyHeaders(const Fields& fields, HttpResponse& out) {
  for (const auto& f : fields) {
    std::string name(f.name_string());
    for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    out.headers[name] = std::string(f.value());
  }
}
}  // namespace

std::string HttpResponse::contentType() const {
  auto it = headers.find("content-type");
  return it == headers.end() ? std::string() : it->second;
}

HttpClient::HttpClient(const std::string& server, std::string token, std::chrono::seconds timeout)
    : server_(server), token_(std::move(token)), timeout_(timeout) {
  constexpr std::string_view scheme = "http://";
  if (server.rfind(scheme, 0) != 0)
    throw std::invalid_argument("server URL must start with http:// (got \"" + server + "\")");
  std::string rest = server.substr(scheme.size());
  if (auto slash = rest.find('/'); slash != std::string::npos) rest.resize(slash);
  const auto colon = rest.rfind(':');
  if (colon == std::string::npos || rest.back() == ']') {
    host_ = rest;
    port_ = "80";
  } else {
    host_ = rest.substr(0, colon);
    port_ = rest.substr(colon + 1);
  }
  if (host_.size() >= 2 && host_.front() == '[') host_ = host_.substr(1, host_.size() - 2);
  if (host_.empty()) throw std::invalid_argument("server URL has no host: \"" + server + "\"");
}

namespace {

/// A connection to the server within `timeout`; every later send and receive on it fails after
/// `timeout` without progress (SO_SNDTIMEO / SO_RCVTIMEO), so a stopped server cannot hang the client.
void connect(net::io_context& ioc, beast::tcp_stream& stream, const std::string& host, const std::string& port,
             const std::string& server, std::chrono::seconds timeout) {
  tcp::resolver resolver(ioc);
  beast::error_code ec;
  auto results = resolver.resolve(host, port, ec);
  if (ec) throw ConnectionError("cannot resolve " + server + ": " + ec.message());
  stream.expires_after(timeout);
  beast::error_code connectEc = net::error::would_block;
  stream.async_connect(results, [&](beast::error_code e, const tcp::endpoint&) { connectEc = e; });
  ioc.run();
  ioc.restart();
  if (connectEc == beast::error::timeout)
    throw ConnectionError("no connection to " + server + " within " + std::to_string(timeout.count()) +
                          " s (is rcfd-server running and reachable? --timeout or RCFD_TIMEOUT)");
  if (connectEc)
    throw ConnectionError("cannot connect to " + server + ": " + connectEc.message() +
                          " (is rcfd-server running? set --server or RCFD_SERVER)");
  stream.expires_never();
}

/// Runs one asynchronous operation on `stream` to its end, cancelled after `timeout` without it
/// completing (Beast's stream timeout: a stopped server cannot hang the client).
template <class Start>
beast::error_code runFor(net::io_context& ioc, beast::tcp_stream& stream, std::chrono::seconds timeout, Start&& start) {
  beast::error_code result = net::error::would_block;
  stream.expires_after(timeout);
  start([&](beast::error_code e, std::size_t) { result = e; });
  ioc.run();
  ioc.restart();
  stream.expires_never();
  return result;
}

/// Reads a message into `parser`, each piece within `timeout` (an idle limit, not a total one: a large
/// download may take as long as it keeps arriving).
template <class Parser>
beast::error_code readWithin(net::io_context& ioc, beast::tcp_stream& stream, beast::flat_buffer& buffer,
                             Parser& parser, std::chrono::seconds timeout, bool headerOnly = false) {
  while (headerOnly ? !parser.is_header_done() : !parser.is_done()) {
    const auto ec = runFor(ioc, stream, timeout, [&](auto&& done) { http::async_read_some(stream, buffer, parser, done); });
    if (ec) return ec;
  }
  return {};
}

/// The message of a failed read or write: a timeout says so.
std::string failure(const beast::error_code& ec, std::chrono::seconds timeout) {
  if (ec == beast::error::timeout)
    return "no answer within " + std::to_string(timeout.count()) + " s (--timeout or RCFD_TIMEOUT)";
  return ec.message();
}

template <class RequestBody, class ResponseParser>
void exchange(const std::string& host, const std::string& port, http::request<RequestBody>& req,
              ResponseParser& parser, const std::string& server, std::chrono::seconds timeout) {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  connect(ioc, stream, host, port, server, timeout);
  req.prepare_payload();
  beast::error_code ec = runFor(ioc, stream, timeout, [&](auto&& done) { http::async_write(stream, req, done); });
  beast::flat_buffer buffer;
  // The server may answer early (e.g. 413) and close while we still send: read its answer anyway.
  const beast::error_code readEc = readWithin(ioc, stream, buffer, parser, timeout);
  if (readEc) throw ConnectionError("no valid answer from " + server + ": " + failure(ec && ec != beast::error::timeout ? ec : readEc, timeout));
  stream.socket().shutdown(tcp::socket::shutdown_both, ec);
}

}  // namespace

HttpResponse HttpClient::get(const std::string& target) {
  http::request<http::empty_body> req{http::verb::get, target, 11};
  req.set(http::field::host, host_);
  if (!token_.empty()) req.set(http::field::authorization, "Bearer " + token_);
  http::response_parser<http::string_body> parser;
  parser.body_limit(kMaxResponseBody);
  exchange(host_, port_, req, parser, server_, timeout_);
  HttpResponse out;
  out.status = parser.get().result_int();
  copyHeaders(parser.get(), out);
  out.body = parser.get().body();
  return out;
}

HttpResponse HttpClient::post(const std::string& target, const std::string& jsonBody,
                              const std::map<std::string, std::string>& headers) {
  http::request<http::string_body> req{http::verb::post, target, 11};
  req.set(http::field::host, host_);
  req.set(http::field::content_type, "application/json");
  if (!token_.empty()) req.set(http::field::authorization, "Bearer " + token_);
  for (const auto& [k, v] : headers) req.set(k, v);
  req.body() = jsonBody;
  http::response_parser<http::string_body> parser;
  parser.body_limit(kMaxResponseBody);
  exchange(host_, port_, req, parser, server_, timeout_);
  HttpResponse out;
  out.status = parser.get().result_int();
  copyHeaders(parser.get(), out);
  out.body = parser.get().body();
  return out;
}

HttpResponse HttpClient::postFile(const std::string& target, const std::filesystem::path& file) {
  http::request<http::file_body> req{http::verb::post, target, 11};
  req.set(http::field::host, host_);
  req.set(http::field::content_type, "application/x-hdf5");
  if (!token_.empty()) req.set(http::field::authorization, "Bearer " + token_);
  beast::error_code ec;
  req.body().open(file.c_str(), beast::file_mode::scan, ec);
  if (ec) throw std::runtime_error("cannot read " + file.string() + ": " + ec.message());
  http::response_parser<http::string_body> parser;
  exchange(host_, port_, req, parser, server_, timeout_);
  HttpResponse out;
  out.status = parser.get().result_int();
  copyHeaders(parser.get(), out);
  out.body = parser.get().body();
  return out;
}

HttpResponse HttpClient::download(const std::string& target, const std::filesystem::path& file) {
  // Read the header first: only a 2xx body goes to the file, an error body stays in memory.
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  connect(ioc, stream, host_, port_, server_, timeout_);
  beast::error_code ec;
  http::request<http::empty_body> req{http::verb::get, target, 11};
  req.set(http::field::host, host_);
  if (!token_.empty()) req.set(http::field::authorization, "Bearer " + token_);
  ec = runFor(ioc, stream, timeout_, [&](auto&& done) { http::async_write(stream, req, done); });
  if (ec) throw ConnectionError("cannot send to " + server_ + ": " + failure(ec, timeout_));
  beast::flat_buffer buffer;
  http::response_parser<http::empty_body> header;
  header.body_limit(kMaxResponseBody);
  ec = readWithin(ioc, stream, buffer, header, timeout_, /*headerOnly=*/true);
  if (ec) throw ConnectionError("no valid answer from " + server_ + ": " + failure(ec, timeout_));
  HttpResponse out;
  out.status = header.get().result_int();
  copyHeaders(header.get(), out);
  if (out.ok()) {
    const auto partial = file.string() + ".part";
    http::response_parser<http::file_body> body(std::move(header));
    body.body_limit(kMaxResponseBody);
    body.get().body().open(partial.c_str(), beast::file_mode::write, ec);
    if (ec) throw std::runtime_error("cannot write " + partial + ": " + ec.message());
    ec = readWithin(ioc, stream, buffer, body, timeout_);
    body.get().body().close();
    if (ec) {
      std::filesystem::remove(partial);
      throw ConnectionError("download from " + server_ + " broke off: " + failure(ec, timeout_));
    }
    std::filesystem::rename(partial, file);
  } else {
    http::response_parser<http::string_body> body(std::move(header));
    ec = readWithin(ioc, stream, buffer, body, timeout_);
    out.body = body.get().body();
  }
  stream.socket().shutdown(tcp::socket::shutdown_both, ec);
  return out;
}

}  // namespace rcfd::client
