#include "Listener.hpp"

#include <boost/asio/strand.hpp>
#include <boost/beast/core/bind_handler.hpp>
#include <iostream>

#include "HttpSession.hpp"

namespace rcfd::server {

namespace net = boost::asio;

Listener::Listener(net::io_context& ioc, net::ip::tcp::endpoint endpoint, Router& router,
                   net::thread_pool& blocking)
    : ioc_(ioc), acceptor_(net::make_strand(ioc)), router_(router), blocking_(blocking) {
  acceptor_.open(endpoint.protocol());
  acceptor_.set_option(net::socket_base::reuse_address(true));
  acceptor_.bind(endpoint);
  acceptor_.listen(net::socket_base::max_listen_connections);
}

void Listener::run() { doAccept(); }

void Listener::stop(std::function<void()> then) {
  net::post(acceptor_.get_executor(), [self = shared_from_this(), then = std::move(then)] {
    boost::system::error_code ignored;
    self->acceptor_.close(ignored);
    if (then) then();
  });
}

void Listener::doAccept() {
  // Each connection gets its own strand: its handlers never run concurrently.
  acceptor_.async_accept(net::make_strand(ioc_),
                         boost::beast::bind_front_handler(&Listener::onAccept, shared_from_this()));
}

void Listener::onAccept(boost::system::error_code ec, net::ip::tcp::socket socket) {
  if (ec == net::error::operation_aborted || !acceptor_.is_open()) return;
  if (ec) {
    std::cerr << "rcfd-server: accept: " << ec.message() << "\n";
  } else {
    std::make_shared<HttpSession>(std::move(socket), router_, blocking_)->run();
  }
  doAccept();
}

}  // namespace rcfd::server
