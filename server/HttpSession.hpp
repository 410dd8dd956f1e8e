#pragma once
/// \file HttpSession.hpp
/// One HTTP/1.1 connection, after Beast 1.74's advanced server: every handler runs on the
/// connection's strand; each message gets a fresh parser (header first, then a body parser chosen
/// by the route: a string body with the JSON size limit, or a file body for database uploads with
/// their own limit); a request without the token is answered 401 from its header, before any limit
/// or syntax of its body is judged; reads time out (expires_after). Responses are written one at a
/// time, so the response queue of the Beast example has length one here: requests are read again
/// only once the previous response is out. The response to a HEAD request is its header only (RFC
/// 9110 9.3.2), whatever the route answered, so the next response on the connection is not read
/// from its body. Uploads are validated on the blocking pool (which waits for the validating child
/// process, DatabasesApi), never on an io thread.
///
/// The session is a template on its stream: PlainStream (HTTP) or TlsStream (HTTPS, --tls-cert): the
/// TLS session first does the handshake (within the idle time before a token) and ends with a TLS
/// close_notify instead of a TCP half-close; everything between is the same code, and the plain
/// session has no branch or indirection it did not have before.

#include <boost/asio/thread_pool.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <array>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <type_traits>

#include "HttpTypes.hpp"
#include "Router.hpp"
#include "Users.hpp"

namespace rcfd::server {

using PlainStream = boost::beast::tcp_stream;
using TlsStream = boost::beast::ssl_stream<boost::beast::tcp_stream>;

template <class Stream>
class HttpSession : public std::enable_shared_from_this<HttpSession<Stream>> {
 public:
  static constexpr bool kTls = std::is_same_v<Stream, TlsStream>;

  /// `ticket` is held as long as the connection is open (the listener's count of open connections).
  HttpSession(boost::asio::ip::tcp::socket&& socket, Router& router, boost::asio::thread_pool& blocking,
              std::shared_ptr<void> ticket = {})
    requires(!kTls);
  /// An HTTPS connection with the server's certificate and key in `tls`.
  HttpSession(boost::asio::ip::tcp::socket&& socket, boost::asio::ssl::context& tls, Router& router,
              boost::asio::thread_pool& blocking, std::shared_ptr<void> ticket = {})
    requires(kTls);
  ~HttpSession();
  /// Starts the session (the TLS handshake, then reading) on its strand.
  void run();

 private:
  boost::beast::tcp_stream& tcp() { return boost::beast::get_lowest_layer(stream_); }
  void onHandshake(boost::beast::error_code ec);
  /// Ends a TLS connection whose peer said goodbye: our close_notify, then the socket is closed.
  void tlsShutdown();
  void doRead();
  void onHeader(boost::beast::error_code ec, std::size_t);
  void onBody(boost::beast::error_code ec, std::size_t);
  void onUpload(boost::beast::error_code ec, std::size_t);
  /// Sends one response; `keepAlive` false closes the connection after it (draining unread input).
  void send(Response&& res, bool keepAlive);
  void onWrite(bool close, boost::beast::error_code ec, std::size_t);
  void lingeringClose();
  void onDrain(boost::beast::error_code ec, std::size_t n);
  void readError(boost::beast::error_code ec);
  /// The problem `instance` of a request whose read failed: its path, as far as it was received.
  std::string instanceOfFailedRead() const;
  /// Whether the request whose read failed is a HEAD: known once its request line was parsed, else
  /// read from the request line still unread in the buffer.
  bool failedReadIsHead() const;

  Stream stream_;
  boost::beast::flat_buffer buffer_;
  Router& router_;
  boost::asio::thread_pool& blocking_;
  std::optional<http::request_parser<http::empty_body>> header_;
  std::optional<http::request_parser<http::string_body>> body_;
  std::optional<http::request_parser<http::file_body>> upload_;
  std::filesystem::path uploadPath_;
  std::shared_ptr<void> response_;  // the message being written
  std::chrono::steady_clock::time_point started_;
  int status_ = 0;
  std::size_t drained_ = 0;
  std::array<char, 16384> scratch_{};
  std::shared_ptr<void> ticket_;
  std::optional<Caller> caller_;  ///< whom the request being answered came from (Router::authenticate)
  bool tokenSeen_ = false;  ///< a request carried an Authorization header: the long idle time applies
  bool head_ = false;       ///< the request answered is a HEAD: its response goes without a body
};

}  // namespace rcfd::server
