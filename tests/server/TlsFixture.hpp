#pragma once
// HTTPS for server tests: a self-signed certificate made with the openssl command line, and one
// request over TLS (Boost.Beast over OpenSSL) that checks the server's certificate against it.

#include <boost/beast/ssl.hpp>
#include <openssl/ssl.h>
#include <openssl/x509v3.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "ServerFixture.hpp"

namespace rcfd::test {

struct Certificate {
  std::filesystem::path cert, key;
};

/// A fresh self-signed P-256 certificate valid for a day, for the names in `subjectAltName`
/// ("IP:127.0.0.1,DNS:localhost"), written into `dir` as cert.pem and key.pem (mode 0600).
inline Certificate selfSignedCertificate(const std::filesystem::path& dir,
                                         const std::string& subjectAltName = "IP:127.0.0.1,DNS:localhost") {
  std::filesystem::create_directories(dir);
  Certificate c{dir / "cert.pem", dir / "key.pem"};
  const std::string command = "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 1 "
                              "-subj /CN=rcfd-test -addext subjectAltName=" + subjectAltName +
                              " -keyout '" + c.key.string() + "' -out '" + c.cert.string() + "' 2>/dev/null";
  if (std::system(command.c_str()) != 0 || !std::filesystem::exists(c.cert))
    throw std::runtime_error("openssl could not make a certificate: " + command);
  std::filesystem::permissions(c.key, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  return c;
}

/// One HTTPS exchange on a new connection to 127.0.0.1, the server's certificate checked against
/// `caFile` and the address; throws std::runtime_error when the handshake or the exchange fails.
inline Reply httpsRequest(unsigned short port, const std::filesystem::path& caFile, boost::beast::http::verb method,
                          const std::string& target, const std::string& token = {}, const std::string& body = {}) {
  namespace http = boost::beast::http;
  namespace ssl = boost::asio::ssl;
  boost::asio::io_context ioc;
  ssl::context context(ssl::context::tls_client);
  context.set_verify_mode(ssl::verify_peer);
  context.load_verify_file(caFile.string());
  boost::beast::ssl_stream<boost::beast::tcp_stream> stream(ioc, context);
  X509_VERIFY_PARAM_set1_ip_asc(SSL_get0_param(stream.native_handle()), "127.0.0.1");
  boost::beast::get_lowest_layer(stream).connect(
      boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
  boost::beast::error_code ec;
  stream.handshake(ssl::stream_base::client, ec);
  if (ec) throw std::runtime_error("TLS handshake failed: " + ec.message());
  http::request<http::string_body> req{method, target, 11};
  req.set(http::field::host, "127.0.0.1");
  if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
  if (!body.empty() || method == http::verb::post) {
    req.set(http::field::content_type, "application/json");
    req.body() = body;
  }
  req.prepare_payload();
  boost::beast::error_code writeEc;
  http::write(stream, req, writeEc);  // the server may answer early (401, 413) and stop reading
  boost::beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(1ull << 30);
  http::read(stream, buffer, parser, ec);
  if (ec) throw std::runtime_error("https read failed: " + ec.message());
  stream.shutdown(ec);  // close_notify both ways: the server answers ours
  return replyOf(parser.get());
}

}  // namespace rcfd::test
