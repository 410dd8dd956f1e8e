#include "Listener.hpp"

#include <boost/asio/strand.hpp>
#include <boost/beast/core/bind_handler.hpp>
#include <iostream>

#include "HttpSession.hpp"
#include "Router.hpp"
#include "ServerConfig.hpp"

namespace rcfd::server {

namespace net = boost::asio;

Listener::Listener(net::io_context& ioc, net::ip::tcp::endpoint endpoint, Router& router,
                   net::thread_pool& blocking, net::ssl::context* tls)
    : ioc_(ioc), acceptor_(net::make_strand(ioc)), router_(router), blocking_(blocking), tls_(tls),
      retry_(acceptor_.get_executor()) {
  acceptor_.open(endpoint.protocol());
  acceptor_.set_option(net::socket_base::reuse_address(true));
  acceptor_.bind(endpoint);
  acceptor_.listen(net::socket_base::max_listen_connections);
}

void Listener::run() { doAccept(); }

void Listener::stop(std::function<void()> then) {
  net::post(acceptor_.get_executor(), [self = shared_from_this(), then = std::move(then)] {
    boost::system::error_code ignored;
    self->retry_.cancel();
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
    // Typically descriptors used up (EMFILE): retrying at once would spin on the same error.
    logLimited("rcfd-server: accept: " + ec.message() + "; retrying with back-off");
    backoff_ = std::min<std::chrono::milliseconds>(std::chrono::seconds(1),
                                                   std::max<std::chrono::milliseconds>(std::chrono::milliseconds(10), 2 * backoff_));
    retry_.expires_after(backoff_);
    retry_.async_wait([self = shared_from_this()](boost::system::error_code wait) {
      if (!wait) self->doAccept();
    });
    return;
  }
  backoff_ = std::chrono::milliseconds(0);
  boost::system::error_code peerError;
  const auto peer = socket.remote_endpoint(peerError);
  auto ticket = admit(peerError ? std::string("?") : peer.address().to_string());
  if (!ticket) {
    logLimited("rcfd-server: connection from " + (peerError ? std::string("?") : peer.address().to_string()) +
               " closed: over the limit of open connections");
    boost::system::error_code ignored;
    socket.close(ignored);
  } else if (tls_) {
    std::make_shared<HttpSession<TlsStream>>(std::move(socket), *tls_, router_, blocking_, std::move(ticket))->run();
  } else {
    std::make_shared<HttpSession<PlainStream>>(std::move(socket), router_, blocking_, std::move(ticket))->run();
  }
  doAccept();
}

std::shared_ptr<void> Listener::admit(const std::string& peer) {
  const ServerConfig& config = router_.config();
  std::lock_guard lock(counts_->mutex);
  int& fromPeer = counts_->perPeer[peer];
  if (counts_->total >= config.maxConnections || fromPeer >= config.maxConnectionsPerPeer) {
    if (fromPeer == 0) counts_->perPeer.erase(peer);
    return nullptr;
  }
  ++counts_->total, ++fromPeer;
  struct Ticket {
    std::shared_ptr<Counts> counts;
    std::string peer;
    ~Ticket() {
      if (!counts) return;
      std::lock_guard lock(counts->mutex);
      --counts->total;
      if (--counts->perPeer[peer] <= 0) counts->perPeer.erase(peer);
    }
  };
  auto ticket = std::make_shared<Ticket>();  // filled in place: a copied Ticket would release twice
  ticket->counts = counts_;
  ticket->peer = peer;
  return ticket;
}

void Listener::logLimited(const std::string& line) {
  const auto now = std::chrono::steady_clock::now();
  if (lastLog_.time_since_epoch().count() != 0 && now - lastLog_ < std::chrono::seconds(10)) {
    ++suppressedLines_;
    return;
  }
  std::cerr << line;
  if (suppressedLines_ > 0) std::cerr << " (" << suppressedLines_ << " similar lines in the last 10 s left out)";
  std::cerr << "\n";
  lastLog_ = now, suppressedLines_ = 0;
}

}  // namespace rcfd::server
