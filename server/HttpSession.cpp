#include "HttpSession.hpp"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <limits>

#include "Problem.hpp"

namespace rcfd::server {

namespace beast = boost::beast;
namespace net = boost::asio;

namespace {
constexpr std::uint32_t kHeaderLimit = 16 * 1024;     // bytes of a request header
constexpr std::size_t kDrainLimit = 64u << 20;        // unread body bytes discarded before closing
constexpr auto kDrainTimeout = std::chrono::seconds(5);

/// The response with its header (Content-Length included) and no body: the answer to a HEAD.
Response withoutBody(Response&& res) {
  return std::visit([](auto& message) -> Response { return StringResponse(std::move(message.base())); }, res);
}

/// Ends of a read that are the peer going away, not a request to answer: the connection just closes.
/// Over TLS this includes a TCP close without close_notify (stream_truncated) and any TLS failure: a
/// stream that broke cannot carry an answer.
bool isPeerGone(const beast::error_code& ec) {
  return ec == http::error::end_of_stream || ec == net::error::eof || ec == net::error::connection_reset ||
         ec == beast::error::timeout || ec == net::error::operation_aborted ||
         ec == net::ssl::error::stream_truncated || ec.category() == net::error::get_ssl_category();
}
}  // namespace

template <class Stream>
HttpSession<Stream>::HttpSession(net::ip::tcp::socket&& socket, Router& router, net::thread_pool& blocking,
                                 std::shared_ptr<void> ticket)
  requires(!kTls)
    : stream_(std::move(socket)), router_(router), blocking_(blocking), ticket_(std::move(ticket)) {}

template <class Stream>
HttpSession<Stream>::HttpSession(net::ip::tcp::socket&& socket, net::ssl::context& tls, Router& router,
                                 net::thread_pool& blocking, std::shared_ptr<void> ticket)
  requires(kTls)
    : stream_(std::move(socket), tls), router_(router), blocking_(blocking), ticket_(std::move(ticket)) {}

template <class Stream>
HttpSession<Stream>::~HttpSession() {
  if (!uploadPath_.empty()) {
    std::error_code ec;
    std::filesystem::remove(uploadPath_, ec);  // an interrupted upload leaves nothing behind
  }
}

template <class Stream>
void HttpSession<Stream>::run() {
  if constexpr (kTls) {
    net::dispatch(stream_.get_executor(), [self = this->shared_from_this()] {
      // The handshake precedes any token: it gets the short idle time of a connection without one.
      const auto& config = self->router_.config();
      self->tcp().expires_after(std::min(config.readTimeout, config.idleBeforeToken));
      self->stream_.async_handshake(net::ssl::stream_base::server,
                                    beast::bind_front_handler(&HttpSession::onHandshake, self));
    });
  } else {
    net::dispatch(stream_.get_executor(),
                  beast::bind_front_handler(&HttpSession::doRead, this->shared_from_this()));
  }
}

template <class Stream>
void HttpSession<Stream>::onHandshake(beast::error_code ec) {
  if (!ec) return doRead();
  // Not TLS (a plain HTTP request to the HTTPS port), an unacceptable version, or too slow: there is
  // no channel to answer on.
  beast::error_code ignored;
  tcp().socket().close(ignored);
}

template <class Stream>
void HttpSession<Stream>::tlsShutdown() {
  if constexpr (kTls) {
    tcp().expires_after(kDrainTimeout);
    stream_.async_shutdown([self = this->shared_from_this()](beast::error_code) {
      beast::error_code ignored;
      self->tcp().socket().close(ignored);
    });
  }
}

template <class Stream>
void HttpSession<Stream>::doRead() {
  header_.emplace();
  header_->header_limit(kHeaderLimit);
  caller_.reset();
  // No limit here: the route's own limit is checked against Content-Length once the route is known
  // (onHeader), and the route's body parser enforces it on chunked bodies.
  // (Not boost::none: Beast 1.74 compares a Content-Length with an empty optional as "over".)
  header_->body_limit(std::numeric_limits<std::uint64_t>::max());
  body_.reset();
  upload_.reset();
  head_ = false;
  // A connection that never sent a token holds a descriptor for a few seconds only.
  const auto& config = router_.config();
  tcp().expires_after(tokenSeen_ ? config.readTimeout : std::min(config.readTimeout, config.idleBeforeToken));
  http::async_read_header(stream_, buffer_, *header_,
                          beast::bind_front_handler(&HttpSession::onHeader, this->shared_from_this()));
}

template <class Stream>
void HttpSession<Stream>::readError(beast::error_code ec) {
  if constexpr (kTls) {
    if (isPeerGone(ec)) {
      // A peer that said goodbye (close_notify) gets ours; one that broke the stream, nothing.
      if (ec == http::error::end_of_stream || ec == net::error::eof) return tlsShutdown();
      beast::error_code ignored;
      tcp().socket().close(ignored);
      return;
    }
  } else if (isPeerGone(ec)) {
    beast::error_code ignored;
    stream_.socket().shutdown(net::ip::tcp::socket::shutdown_send, ignored);
    return;
  }
  started_ = std::chrono::steady_clock::now();
  head_ = failedReadIsHead();
  const std::string instance = instanceOfFailedRead();
  if (ec == http::error::body_limit) {
    send(problem(http::status::payload_too_large, "body-too-large", "Request body too large",
                 "the body exceeds the limit of this endpoint", instance),
         false);
    return;
  }
  if (ec == http::error::header_limit) {
    send(problem(http::status::request_header_fields_too_large, "header-too-large",
                 "Request header too large", "the header exceeds 16 KiB", instance),
         false);
    return;
  }
  send(problem(http::status::bad_request, "malformed-http", "Malformed HTTP request", ec.message(), instance),
       false);
}

template <class Stream>
std::string HttpSession<Stream>::instanceOfFailedRead() const {
  // The parser that failed holds the target once it has read the request line. The header is parsed
  // only when complete, so a header over the limit fails before that: then the target is taken from
  // the request line still unread in the buffer.
  std::string_view target;
  if (body_) target = std::string_view(body_->get().target().data(), body_->get().target().size());
  else if (upload_) target = std::string_view(upload_->get().target().data(), upload_->get().target().size());
  else if (header_) target = std::string_view(header_->get().target().data(), header_->get().target().size());
  if (target.empty()) {
    const auto unread = buffer_.data();
    std::string_view requestLine(static_cast<const char*>(unread.data()), unread.size());
    requestLine = requestLine.substr(0, std::min(requestLine.find('\r'), requestLine.find('\n')));
    if (const auto space = requestLine.find(' '); space != std::string_view::npos) {
      target = requestLine.substr(space + 1);
      target = target.substr(0, target.find(' '));
    }
  }
  return instancePath(target);
}

template <class Stream>
bool HttpSession<Stream>::failedReadIsHead() const {
  if (body_ || upload_) return head_;
  if (header_ && header_->get().method() == http::verb::head) return true;  // its request line was parsed
  const auto unread = buffer_.data();
  const std::string_view requestLine(static_cast<const char*>(unread.data()), unread.size());
  return requestLine.rfind("HEAD ", 0) == 0;
}

template <class Stream>
void HttpSession<Stream>::onHeader(beast::error_code ec, std::size_t) {
  if (ec) return readError(ec);
  started_ = std::chrono::steady_clock::now();
  const auto& req = header_->get();
  head_ = req.method() == http::verb::head;
  tokenSeen_ = tokenSeen_ || req.find(http::field::authorization) != req.end();
  tcp().expires_after(router_.config().readTimeout);  // the body may take the full read time
  const std::string_view target(req.target().data(), req.target().size());
  const std::string instance = instancePath(target);
  // Nothing about a request (its size, its body's syntax) is judged for a client without the token:
  // it gets 401 before its body is read, and the connection closes, discarding that body.
  caller_ = router_.authenticate(req);
  if (!Router::isPublic(req.method(), target) && !caller_)
    return send(router_.unauthorized(instance), false);
  const auto tooLarge = [&](std::uint64_t length, std::uint64_t limit) {
    return problem(http::status::payload_too_large, "body-too-large", "Request body too large",
                   "the body has " + std::to_string(length) + " bytes; the limit is " +
                       std::to_string(limit),
                   instance);
  };
  const auto length = header_->content_length();
  if (Router::isUpload(req.method(), target)) {
    if (length && *length > router_.config().uploadLimit)
      return send(tooLarge(*length, router_.config().uploadLimit), false);
    upload_.emplace(std::move(*header_));
    upload_->body_limit(router_.config().uploadLimit);
    uploadPath_ = router_.databases().temporaryUploadPath();
    beast::error_code fileError;
    upload_->get().body().open(uploadPath_.c_str(), beast::file_mode::write, fileError);
    if (fileError)
      return send(problem(http::status::internal_server_error, "storage-failed", "Storage failed",
                          "cannot create the upload file: " + fileError.message(), instance),
                  false);
    tcp().expires_after(router_.config().uploadTimeout);
    http::async_read(stream_, buffer_, *upload_,
                     beast::bind_front_handler(&HttpSession::onUpload, this->shared_from_this()));
    return;
  }
  if (length && *length > router_.config().jsonBodyLimit)
    return send(tooLarge(*length, router_.config().jsonBodyLimit), false);
  body_.emplace(std::move(*header_));
  body_->body_limit(router_.config().jsonBodyLimit);
  if (body_->is_done()) return onBody({}, 0);  // no body (a GET): answer without another read
  http::async_read(stream_, buffer_, *body_,
                   beast::bind_front_handler(&HttpSession::onBody, this->shared_from_this()));
}

template <class Stream>
void HttpSession<Stream>::onBody(beast::error_code ec, std::size_t) {
  if (ec) return readError(ec);
  started_ = std::chrono::steady_clock::now();
  Request req = body_->release();
  const bool keepAlive = req.keep_alive();
  // Handlers only read and write short SQLite rows or small files, so they run here on the strand.
  send(router_.handle(req, caller_), keepAlive);
}

template <class Stream>
void HttpSession<Stream>::onUpload(beast::error_code ec, std::size_t) {
  if (ec) return readError(ec);
  auto req = upload_->release();
  req.body().close();
  const bool keepAlive = req.keep_alive();
  const auto target = parseTarget(std::string(req.target()));
  // Validation opens the HDF5 file: off the io threads, then back to this strand to answer.
  // The header was authenticated (onHeader): an upload always has its caller.
  net::post(blocking_, [self = this->shared_from_this(), keepAlive, target, caller = *caller_] {
    auto path = self->uploadPath_;
    StringResponse res =
        self->router_.databases().accept(path, target.value_or(Target{"/v1/databases", {}, {}, false}), caller);
    net::post(self->stream_.get_executor(), [self, keepAlive, res = std::move(res)]() mutable {
      self->uploadPath_.clear();  // moved into place or deleted by accept()
      self->send(std::move(res), keepAlive);
    });
  });
}

template <class Stream>
void HttpSession<Stream>::send(Response&& res, bool keepAlive) {
  if (head_) res = withoutBody(std::move(res));
  std::visit(
      [&](auto& message) {
        using Message = std::decay_t<decltype(message)>;
        auto sp = std::make_shared<Message>(std::move(message));
        sp->keep_alive(keepAlive);
        sp->set(http::field::server, "rcfd-server");
        status_ = static_cast<int>(sp->result_int());
        response_ = sp;
        http::async_write(stream_, *sp,
                          beast::bind_front_handler(&HttpSession::onWrite, this->shared_from_this(),
                                                    sp->need_eof()));
      },
      res);
}

template <class Stream>
void HttpSession<Stream>::onWrite(bool close, beast::error_code ec, std::size_t) {
  router_.metrics().observe(
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count(), status_);
  response_.reset();
  if (ec) return;
  if (close) return lingeringClose();
  doRead();
}

template <class Stream>
void HttpSession<Stream>::lingeringClose() {
  // Closing with unread request bytes makes the kernel send RST, which can destroy the response
  // before the client reads it; so shut down our side and discard input for a while first. Over TLS
  // "our side" is a close_notify first.
  if constexpr (kTls) {
    tcp().expires_after(kDrainTimeout);
    stream_.async_shutdown([self = this->shared_from_this()](beast::error_code ec) {
      beast::error_code ignored;
      if (!ec) {  // close_notify both ways: done
        self->tcp().socket().close(ignored);
        return;
      }
      // Our close_notify is out (OpenSSL sends it before it fails), but the peer is still sending (the
      // body of a request answered from its header), which TLS refuses after close_notify ("application
      // data after close notify"): that rest is read and discarded below TLS, as the plain drain does.
      self->tcp().socket().shutdown(net::ip::tcp::socket::shutdown_send, ignored);
      self->tcp().async_read_some(net::buffer(self->scratch_),
                                  beast::bind_front_handler(&HttpSession::onDrain, self));
    });
  } else {
    beast::error_code ignored;
    stream_.socket().shutdown(net::ip::tcp::socket::shutdown_send, ignored);
    stream_.expires_after(kDrainTimeout);
    stream_.async_read_some(net::buffer(scratch_),
                            beast::bind_front_handler(&HttpSession::onDrain, this->shared_from_this()));
  }
}

template <class Stream>
void HttpSession<Stream>::onDrain(beast::error_code ec, std::size_t n) {
  drained_ += n;
  if (ec || drained_ > kDrainLimit) {
    beast::error_code ignored;
    tcp().socket().close(ignored);
    return;
  }
  tcp().async_read_some(net::buffer(scratch_),
                        beast::bind_front_handler(&HttpSession::onDrain, this->shared_from_this()));
}

template class HttpSession<PlainStream>;
template class HttpSession<TlsStream>;

}  // namespace rcfd::server
