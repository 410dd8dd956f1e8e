#pragma once
/// \file Listener.hpp
/// Accepts connections and starts one HttpSession for each, on its own strand.

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/thread_pool.hpp>
#include <functional>
#include <memory>

namespace rcfd::server {

class Router;

class Listener : public std::enable_shared_from_this<Listener> {
 public:
  /// Binds and listens; throws boost::system::system_error if the endpoint cannot be used.
  Listener(boost::asio::io_context& ioc, boost::asio::ip::tcp::endpoint endpoint, Router& router,
           boost::asio::thread_pool& blocking);
  /// The bound endpoint (the real port when 0 was asked for).
  boost::asio::ip::tcp::endpoint endpoint() const { return acceptor_.local_endpoint(); }
  void run();
  /// Closes the listening socket (on its strand, so it never races an accept), then calls `then`:
  /// from then on new connections are refused instead of queueing in a backlog nobody serves.
  void stop(std::function<void()> then = {});

 private:
  void doAccept();
  void onAccept(boost::system::error_code ec, boost::asio::ip::tcp::socket socket);

  boost::asio::io_context& ioc_;
  boost::asio::ip::tcp::acceptor acceptor_;
  Router& router_;
  boost::asio::thread_pool& blocking_;
};

}  // namespace rcfd::server
