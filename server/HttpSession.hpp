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

#include <boost/asio/thread_pool.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>

#include "HttpTypes.hpp"
#include "Router.hpp"

namespace rcfd::server {

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  /// `ticket` is held as long as the connection is open (the listener's count of open connections).
  HttpSession(boost::asio::ip::tcp::socket&& socket, Router& router, boost::asio::thread_pool& blocking,
              std::shared_ptr<void> ticket = {});
  ~HttpSession();
  /// Starts reading on the session's strand.
  void run();

 private:
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

  boost::beast::tcp_stream stream_;
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
  bool tokenSeen_ = false;  ///< a request carried an Authorization header: the long idle time applies
  bool head_ = false;       ///< the request answered is a HEAD: its response goes without a body
};

}  // namespace rcfd::server
