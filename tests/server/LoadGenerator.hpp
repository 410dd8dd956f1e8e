#pragma once
// A small loopback load generator (Boost.Beast, asynchronous): `connections` keep-alive connections
// each sending GET `target` until `duration` has passed, either back to back (interval 0: measures
// the server at saturation) or one request per `interval` per client (a polling client; the clients'
// first requests are spread evenly over one interval, so they do not all poll in the same instant). Used by tests/server/test_load
// (5 s) and bench/server_load.cpp (30 s). Header-only so both can include it.

#include <algorithm>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace rcfd::test {

struct LoadResult {
  std::uint64_t requests = 0;
  std::uint64_t errors = 0;  ///< non-200 answers and broken connections
  double seconds = 0.0;
  double p50Ms = 0.0, p99Ms = 0.0, maxMs = 0.0;
};

namespace detail {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;

struct LoadShared {
  std::mutex mutex;
  std::vector<double> latenciesMs;
  std::uint64_t errors = 0;
  std::chrono::steady_clock::time_point deadline;
  std::chrono::milliseconds interval{0};
};

class LoadConnection : public std::enable_shared_from_this<LoadConnection> {
 public:
  LoadConnection(net::io_context& ioc, LoadShared& shared, net::ip::tcp::endpoint endpoint,
                 const std::string& target, const std::string& token)
      : stream_(net::make_strand(ioc)), timer_(stream_.get_executor()), shared_(shared), endpoint_(endpoint) {
    req_ = {http::verb::get, target, 11};
    req_.set(http::field::host, "127.0.0.1");
    req_.set(http::field::authorization, "Bearer " + token);
    req_.keep_alive(true);
    latencies_.reserve(100000);
  }
  ~LoadConnection() {
    std::lock_guard lock(shared_.mutex);
    shared_.latenciesMs.insert(shared_.latenciesMs.end(), latencies_.begin(), latencies_.end());
    shared_.errors += errors_;
  }
  /// Connects, then sends the first request after `offset` (polling clients are spread over one
  /// interval, as independent clients are, instead of all asking in the same instant).
  void start(std::chrono::steady_clock::duration offset) {
    stream_.async_connect(endpoint_, [self = shared_from_this(), offset](beast::error_code ec) {
      if (ec) {
        ++self->errors_;
        return;
      }
      if (offset.count() == 0) return self->send();
      self->timer_.expires_after(offset);
      self->timer_.async_wait([self](beast::error_code) { self->send(); });
    });
  }

 private:
  void send() {
    if (std::chrono::steady_clock::now() >= shared_.deadline) {
      beast::error_code ignored;
      stream_.socket().shutdown(net::ip::tcp::socket::shutdown_both, ignored);
      return;
    }
    sent_ = std::chrono::steady_clock::now();
    http::async_write(stream_, req_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        ++self->errors_;
        return;
      }
      self->res_ = {};
      http::async_read(self->stream_, self->buffer_, self->res_,
                       [self](beast::error_code ec2, std::size_t) { self->onRead(ec2); });
    });
  }
  void onRead(beast::error_code ec) {
    if (ec) {
      ++errors_;
      return;
    }
    latencies_.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - sent_).count());
    if (res_.result_int() != 200) ++errors_;
    if (shared_.interval.count() == 0) return send();
    // A polling client: the next request one interval after this one was sent.
    timer_.expires_at(sent_ + shared_.interval);
    timer_.async_wait([self = shared_from_this()](beast::error_code) { self->send(); });
  }

  beast::tcp_stream stream_;
  net::steady_timer timer_;
  LoadShared& shared_;
  net::ip::tcp::endpoint endpoint_;
  http::request<http::empty_body> req_;
  http::response<http::string_body> res_;
  beast::flat_buffer buffer_;
  std::chrono::steady_clock::time_point sent_;
  std::vector<double> latencies_;
  std::uint64_t errors_ = 0;
};

}  // namespace detail

inline LoadResult runStatusLoad(unsigned short port, const std::string& token, const std::string& target,
                                int connections, std::chrono::seconds duration, int threads,
                                std::chrono::milliseconds interval = std::chrono::milliseconds(0)) {
  namespace net = boost::asio;
  net::io_context ioc;
  detail::LoadShared shared;
  const auto start = std::chrono::steady_clock::now();
  shared.deadline = start + duration;
  shared.interval = interval;
  const net::ip::tcp::endpoint endpoint(net::ip::make_address("127.0.0.1"), port);
  for (int i = 0; i < connections; ++i)
    std::make_shared<detail::LoadConnection>(ioc, shared, endpoint, target, token)
        ->start(std::chrono::steady_clock::duration(interval) * i / connections);
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back([&ioc] { ioc.run(); });
  ioc.run();
  for (auto& t : pool) t.join();
  LoadResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.requests = shared.latenciesMs.size();
  r.errors = shared.errors;
  auto& l = shared.latenciesMs;
  if (!l.empty()) {
    std::sort(l.begin(), l.end());
    r.p50Ms = l[l.size() / 2];
    r.p99Ms = l[std::min(l.size() - 1, l.size() * 99 / 100)];
    r.maxMs = l.back();
  }
  return r;
}

}  // namespace rcfd::test
