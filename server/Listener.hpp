#pragma once
/// \file Listener.hpp
/// Accepts connections and starts one HttpSession for each, on its own strand. Open connections are
/// capped in total and per peer address (a connection beyond a cap is closed at once); when accept
/// fails (descriptors used up) it retries after a back-off of 10 ms doubling to 1 s instead of at
/// once, and says so on stderr at most once every 10 s. With a TLS context every connection speaks
/// HTTPS (HttpSession<TlsStream>), otherwise plain HTTP.

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/thread_pool.hpp>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

namespace rcfd::server {

class Router;

class Listener : public std::enable_shared_from_this<Listener> {
 public:
  /// Binds and listens; throws boost::system::system_error if the endpoint cannot be used. `tls`
  /// (outliving the listener and its connections) makes it an HTTPS listener.
  Listener(boost::asio::io_context& ioc, boost::asio::ip::tcp::endpoint endpoint, Router& router,
           boost::asio::thread_pool& blocking, boost::asio::ssl::context* tls = nullptr);
  /// The bound endpoint (the real port when 0 was asked for).
  boost::asio::ip::tcp::endpoint endpoint() const { return acceptor_.local_endpoint(); }
  void run();
  /// Closes the listening socket (on its strand, so it never races an accept), then calls `then`:
  /// from then on new connections are refused instead of queueing in a backlog nobody serves.
  void stop(std::function<void()> then = {});

 private:
  void doAccept();
  void onAccept(boost::system::error_code ec, boost::asio::ip::tcp::socket socket);
  /// A ticket for a new connection from `peer`, released when the connection closes; null over a cap.
  std::shared_ptr<void> admit(const std::string& peer);
  /// One stderr line, unless one was written less than 10 s ago (then it is counted and summarised).
  void logLimited(const std::string& line);

  boost::asio::io_context& ioc_;
  boost::asio::ip::tcp::acceptor acceptor_;
  Router& router_;
  boost::asio::thread_pool& blocking_;
  boost::asio::ssl::context* tls_;
  boost::asio::steady_timer retry_;
  std::chrono::milliseconds backoff_{0};
  std::chrono::steady_clock::time_point lastLog_{};
  long suppressedLines_ = 0;
  /// Open connections, shared with the tickets (which outlive neither the listener's strand nor it).
  struct Counts {
    std::mutex mutex;
    int total = 0;
    std::map<std::string, int> perPeer;
  };
  std::shared_ptr<Counts> counts_ = std::make_shared<Counts>();
};

}  // namespace rcfd::server
