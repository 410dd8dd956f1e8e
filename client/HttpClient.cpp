#include "HttpClient.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <openssl/err.h>
#include <openssl/ssl.h>
#include <openssl/x509v3.h>

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

HttpClient::HttpClient(const std::string& server, std::string token, std::chrono::seconds timeout,
                       const std::string& caFile)
    : server_(server), token_(std::move(token)), timeout_(timeout) {
  const bool https = server.rfind("https://", 0) == 0;
  if (!https && server.rfind("http://", 0) != 0)
    throw std::invalid_argument("server URL must start with http:// or https:// (got \"" + server + "\")");
  std::string rest = server.substr(https ? 8 : 7);
  if (auto slash = rest.find('/'); slash != std::string::npos) rest.resize(slash);
  const auto colon = rest.rfind(':');
  if (colon == std::string::npos || rest.back() == ']') {
    host_ = rest;
    port_ = https ? "443" : "80";
  } else {
    host_ = rest.substr(0, colon);
    port_ = rest.substr(colon + 1);
  }
  if (host_.size() >= 2 && host_.front() == '[') host_ = host_.substr(1, host_.size() - 2);
  if (host_.empty()) throw std::invalid_argument("server URL has no host: \"" + server + "\"");
  if (https) {
    tls_ = std::make_shared<net::ssl::context>(net::ssl::context::tls_client);
    SSL_CTX_set_min_proto_version(tls_->native_handle(), TLS1_2_VERSION);
    tls_->set_verify_mode(net::ssl::verify_peer);
    beast::error_code ec;
    if (caFile.empty()) tls_->set_default_verify_paths(ec);
    else tls_->load_verify_file(caFile, ec);
    if (ec)
      throw std::invalid_argument(caFile.empty() ? "cannot load the system's CA certificates: " + ec.message()
                                                 : "--cacert " + caFile + ": not a PEM certificate file (" +
                                                       ec.message() + ")");
  } else if (!caFile.empty()) {
    throw std::invalid_argument("--cacert (RCFD_CACERT) is for https:// servers; " + server + " is http://");
  }
}

HttpClient::~HttpClient() = default;

namespace {

using TlsStream = beast::ssl_stream<beast::tcp_stream>;

/// Runs one asynchronous operation on `stream` to its end, cancelled after `timeout` without it
/// completing (Beast's stream timeout: a stopped server cannot hang the client).
template <class Stream, class Start>
beast::error_code runFor(net::io_context& ioc, Stream& stream, std::chrono::seconds timeout, Start&& start) {
  beast::error_code result = net::error::would_block;
  beast::get_lowest_layer(stream).expires_after(timeout);
  start([&](beast::error_code e, auto&&...) { result = e; });
  ioc.run();
  ioc.restart();
  beast::get_lowest_layer(stream).expires_never();
  return result;
}

/// A connection to the server within `timeout`; every later send and receive on it fails after
/// `timeout` without progress, so a stopped server cannot hang the client.
void connect(net::io_context& ioc, beast::tcp_stream& stream, const std::string& host, const std::string& port,
             const std::string& server, std::chrono::seconds timeout) {
  tcp::resolver resolver(ioc);
  beast::error_code ec;
  auto results = resolver.resolve(host, port, ec);
  if (ec) throw ConnectionError("cannot resolve " + server + ": " + ec.message());
  const auto connectEc = runFor(ioc, stream, timeout, [&](auto&& done) { stream.async_connect(results, done); });
  if (connectEc == beast::error::timeout)
    throw ConnectionError("no connection to " + server + " within " + std::to_string(timeout.count()) +
                          " s (is rcfd-server running and reachable? --timeout or RCFD_TIMEOUT)");
  if (connectEc)
    throw ConnectionError("cannot connect to " + server + ": " + connectEc.message() +
                          " (is rcfd-server running? set --server or RCFD_SERVER)");
}

/// The TLS handshake, the server's certificate checked against the CAs and its name against `host`
/// (an IP address against the certificate's IP addresses).
void handshake(net::io_context& ioc, TlsStream& stream, const std::string& host, const std::string& server,
               std::chrono::seconds timeout) {
  SSL* ssl = stream.native_handle();
  beast::error_code parsed;
  (void)net::ip::make_address(host, parsed);
  const bool isAddress = !parsed;
  X509_VERIFY_PARAM* check = SSL_get0_param(ssl);
  if (isAddress) {
    X509_VERIFY_PARAM_set1_ip_asc(check, host.c_str());
  } else {
    SSL_set_tlsext_host_name(ssl, host.c_str());  // SNI: a server with several names picks this one's
    X509_VERIFY_PARAM_set1_host(check, host.c_str(), 0);
  }
  const auto ec = runFor(ioc, stream, timeout,
                         [&](auto&& done) { stream.async_handshake(net::ssl::stream_base::client, done); });
  if (!ec) return;
  std::string why = ec == beast::error::timeout ? "no answer within " + std::to_string(timeout.count()) + " s"
                                                : ec.message();
  if (const long verify = SSL_get_verify_result(ssl); verify != X509_V_OK)
    why = std::string("the server's certificate is not trusted: ") + X509_verify_cert_error_string(verify) +
          " (give its CA with --cacert or RCFD_CACERT)";
  else if (ec.category() == net::error::get_ssl_category() &&
           ERR_GET_REASON(static_cast<unsigned long>(ec.value())) == SSL_R_WRONG_VERSION_NUMBER)
    why += " (does the server speak HTTPS? A server without --tls-cert is http://)";
  throw ConnectionError("TLS handshake with " + server + " failed: " + why);
}

/// Reads a message into `parser`, each piece within `timeout` (an idle limit, not a total one: a large
/// download may take as long as it keeps arriving).
template <class Stream, class Parser>
beast::error_code readWithin(net::io_context& ioc, Stream& stream, beast::flat_buffer& buffer,
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

/// Closes the connection once the answer is read. Over TLS with close_notify (the server answers
/// with its own), waited for briefly: the answer is complete whatever happens to the goodbye.
void close(net::io_context& ioc, beast::tcp_stream& stream) {
  beast::error_code ignored;
  stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
}
void close(net::io_context& ioc, TlsStream& stream) {
  (void)runFor(ioc, stream, std::chrono::seconds(2), [&](auto&& done) { stream.async_shutdown(done); });
  beast::error_code ignored;
  beast::get_lowest_layer(stream).socket().close(ignored);
}

/// A request with the headers every request of the client carries, in this order: the host, the
/// content type (none: `contentType` null) and the bearer token (none: `token` empty).
template <class Body>
http::request<Body> newRequest(http::verb method, const std::string& target, const std::string& host,
                               const std::string& token, const char* contentType = nullptr) {
  http::request<Body> req{method, target, 11};
  req.set(http::field::host, host);
  if (contentType) req.set(http::field::content_type, contentType);
  if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
  return req;
}

template <class Stream, class RequestBody, class ResponseParser>
void exchange(net::io_context& ioc, Stream& stream, http::request<RequestBody>& req, ResponseParser& parser,
              const std::string& server, std::chrono::seconds timeout) {
  req.prepare_payload();
  beast::error_code ec = runFor(ioc, stream, timeout, [&](auto&& done) { http::async_write(stream, req, done); });
  beast::flat_buffer buffer;
  // The server may answer early (e.g. 413) and close while we still send: read its answer anyway.
  const beast::error_code readEc = readWithin(ioc, stream, buffer, parser, timeout);
  if (readEc) {
    std::string why = failure(ec && ec != beast::error::timeout ? ec : readEc, timeout);
    // An HTTPS server closes a plain connection without a word.
    if constexpr (std::is_same_v<Stream, beast::tcp_stream>)
      if (readEc == http::error::end_of_stream) why += " (if the server speaks HTTPS, use an https:// URL)";
    throw ConnectionError("no valid answer from " + server + ": " + why);
  }
  close(ioc, stream);
}

}  // namespace

template <class Exchange>
void HttpClient::withConnection(Exchange&& exchange) {
  net::io_context ioc;
  if (tls_) {
    TlsStream stream(ioc, *tls_);
    connect(ioc, beast::get_lowest_layer(stream), host_, port_, server_, timeout_);
    handshake(ioc, stream, host_, server_, timeout_);
    exchange(ioc, stream);
  } else {
    beast::tcp_stream stream(ioc);
    connect(ioc, stream, host_, port_, server_, timeout_);
    exchange(ioc, stream);
  }
}

template <class Request>
HttpResponse HttpClient::sendAndRead(Request& req) {
  http::response_parser<http::string_body> parser;
  parser.body_limit(kMaxResponseBody);
  withConnection([&](net::io_context& ioc, auto& stream) { exchange(ioc, stream, req, parser, server_, timeout_); });
  HttpResponse out;
  out.status = parser.get().result_int();
  copyHeaders(parser.get(), out);
  out.body = parser.get().body();
  return out;
}

HttpResponse HttpClient::get(const std::string& target) {
  auto req = newRequest<http::empty_body>(http::verb::get, target, host_, token_);
  return sendAndRead(req);
}

HttpResponse HttpClient::post(const std::string& target, const std::string& jsonBody,
                              const std::map<std::string, std::string>& headers) {
  auto req = newRequest<http::string_body>(http::verb::post, target, host_, token_, "application/json");
  for (const auto& [k, v] : headers) req.set(k, v);
  req.body() = jsonBody;
  return sendAndRead(req);
}

HttpResponse HttpClient::postFile(const std::string& target, const std::filesystem::path& file) {
  auto req = newRequest<http::file_body>(http::verb::post, target, host_, token_, "application/x-hdf5");
  beast::error_code ec;
  req.body().open(file.c_str(), beast::file_mode::scan, ec);
  if (ec) throw std::runtime_error("cannot read " + file.string() + ": " + ec.message());
  return sendAndRead(req);
}

HttpResponse HttpClient::download(const std::string& target, const std::filesystem::path& file) {
  HttpResponse out;
  withConnection([&](net::io_context& ioc, auto& stream) {
    // Read the header first: only a 2xx body goes to the file, an error body stays in memory.
    auto req = newRequest<http::empty_body>(http::verb::get, target, host_, token_);
    auto ec = runFor(ioc, stream, timeout_, [&](auto&& done) { http::async_write(stream, req, done); });
    if (ec) throw ConnectionError("cannot send to " + server_ + ": " + failure(ec, timeout_));
    beast::flat_buffer buffer;
    http::response_parser<http::empty_body> header;
    header.body_limit(kMaxResponseBody);
    ec = readWithin(ioc, stream, buffer, header, timeout_, /*headerOnly=*/true);
    if (ec) throw ConnectionError("no valid answer from " + server_ + ": " + failure(ec, timeout_));
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
    close(ioc, stream);
  });
  return out;
}

}  // namespace rcfd::client
