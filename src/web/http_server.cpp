#include "http_server.h"

#include <array>
#include <optional>
#include <stdexcept>

#include <boost/asio/bind_executor.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/parser.hpp>
#include <boost/beast/http/read.hpp>
#include <boost/beast/http/serializer.hpp>
#include <boost/beast/http/write.hpp>

namespace collision_lab_web {

namespace net = boost::asio;
namespace beast = boost::beast;
using tcp = net::ip::tcp;
using beast::error_code;

const std::vector<std::pair<std::string, std::string>> kSecurityHeaders = {
    {"Content-Security-Policy", "default-src 'self'; frame-ancestors 'none'"},
    {"X-Content-Type-Options", "nosniff"},
    {"X-Frame-Options", "DENY"},
    {"Referrer-Policy", "no-referrer"}};

namespace {

std::chrono::milliseconds duration(double seconds) {
  return std::chrono::milliseconds(static_cast<long long>(seconds * 1000.0));
}

/// A whole answer of the server's own (limits, errors): JSON, then the connection closes.
std::string cannedAnswer(int status, const std::string& reason, const std::string& error) {
  const std::string body = "{\"error\":\"" + error + "\"}";
  std::string text = "HTTP/1.1 " + std::to_string(status) + " " + reason + "\r\n";
  for (const auto& [name, value] : kSecurityHeaders) text += name + ": " + value + "\r\n";
  if (status == 503) text += "Retry-After: 5\r\n";
  text += "Content-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
          "\r\nConnection: close\r\n\r\n" + body;
  return text;
}

}  // namespace

struct HttpServer::Shared {
  HttpLimits limits;
  Handler handler;
  HttpServer::Refused refused;
  std::mutex mutex;
  std::map<std::string, std::size_t> per_address;  ///< open connections by client address [1]
  std::size_t total = 0;                            ///< open connections [1]

  /// Counts a new connection from `client`; false (nothing counted) when over a cap.
  bool admit(const std::string& client) {
    std::lock_guard<std::mutex> lock(mutex);
    auto& mine = per_address[client];
    if (mine >= limits.max_connections_per_address || total >= limits.max_connections) {
      if (mine == 0) per_address.erase(client);
      return false;
    }
    ++mine;
    ++total;
    return true;
  }
  void release(const std::string& client) {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = per_address.find(client);
    if (it != per_address.end() && --it->second == 0) per_address.erase(it);
    --total;
  }
};

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, std::shared_ptr<HttpServer::Shared> shared, std::string client)
      : stream_(std::move(socket)), shared_(std::move(shared)), client_(std::move(client)), timer_(stream_.get_executor()) {}
  ~HttpSession() { shared_->release(client_); }

  void start() { readHeader(shared_->limits.header_timeout); }
  net::any_io_executor executor() { return stream_.get_executor(); }

  template <class Body>
  void write(http::response<Body> response) {
    for (const auto& [name, value] : kSecurityHeaders) response.set(name, value);
    response.keep_alive(keep_alive_ && response.keep_alive());
    response.prepare_payload();
    auto message = std::make_shared<http::response<Body>>(std::move(response));
    auto serializer = std::make_shared<http::response_serializer<Body>>(*message);
    writeSome(message, serializer, [self = shared_from_this(), keep = message->keep_alive()] {
      if (keep) {
        self->readHeader(self->shared_->limits.idle_timeout);
      } else {
        self->close();
      }
    });
  }

  void stream(http::response<http::empty_body> header, std::function<StreamStep()> poll,
              std::chrono::milliseconds interval) {
    for (const auto& [name, value] : kSecurityHeaders) header.set(name, value);
    header.keep_alive(false);
    auto message = std::make_shared<http::response<http::empty_body>>(std::move(header));
    auto serializer = std::make_shared<http::response_serializer<http::empty_body>>(*message);
    poll_ = std::move(poll);
    interval_ = interval;
    writeSome(message, serializer, [self = shared_from_this()] {
      self->watchForClose();
      self->nextPoll();
    });
  }

 private:
  void readHeader(double timeout) {
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(shared_->limits.max_header_bytes));
    parser_->body_limit(shared_->limits.max_body_bytes);
    stream_.expires_after(duration(timeout));
    http::async_read_header(stream_, buffer_, *parser_,
                            [self = shared_from_this()](error_code ec, std::size_t) { self->onHeader(ec); });
  }

  void onHeader(error_code ec) {
    if (ec == http::error::header_limit) return refuse(431, "Request Header Fields Too Large", "the request header is too large");
    // A Content-Length over the limit is refused with the header, before any body is read.
    if (ec == http::error::body_limit) return refuse(413, "Payload Too Large", "the request body is too large");
    if (ec) return close();  // closed, or too slow: the header deadline passed
    stream_.expires_after(duration(shared_->limits.body_timeout));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](error_code ec, std::size_t) { self->onBody(ec); });
  }

  void onBody(error_code ec) {
    if (ec == http::error::body_limit) return refuse(413, "Payload Too Large", "the request body is too large");
    if (ec == beast::error::timeout) return refuse(408, "Request Timeout", "the request body came too slowly");
    if (ec) return close();
    stream_.expires_never();
    HttpRequest request{parser_->release(), client_};
    keep_alive_ = request.message.keep_alive();
    shared_->handler(std::move(request), HttpReply(shared_from_this()));
  }

  /// Answers with one of the server's own errors, then stops sending and discards what the
  /// client still sends for a moment, so that it reads the answer rather than a reset.
  void refuse(int status, const char* reason, const char* error) {
    if (shared_->refused && parser_) {
      const auto& header = parser_->get();
      shared_->refused(client_, std::string(header.method_string()), std::string(header.target()), status, error);
    }
    auto text = std::make_shared<std::string>(cannedAnswer(status, reason, error));
    stream_.expires_after(duration(shared_->limits.write_timeout));
    net::async_write(stream_, net::buffer(*text), [self = shared_from_this(), text](error_code ec, std::size_t) {
      if (ec) return self->close();
      error_code ignored;
      self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
      self->stream_.expires_after(std::chrono::seconds(2));
      self->drain();
    });
  }

  /// At most kDrainBytes for at most 2 s: enough for the answer to be read, little work.
  void drain() {
    stream_.async_read_some(net::buffer(discard_), [self = shared_from_this()](error_code ec, std::size_t n) {
      self->drained_ += n;
      if (ec || self->drained_ > kDrainBytes) return self->close();
      self->drain();
    });
  }

  template <class Message, class Serializer, class Done>
  void writeSome(std::shared_ptr<Message> message, std::shared_ptr<Serializer> serializer, Done done) {
    stream_.expires_after(duration(shared_->limits.write_timeout));
    http::async_write_some(stream_, *serializer,
                           [self = shared_from_this(), message, serializer, done](error_code ec, std::size_t) {
                             if (ec) return self->close();
                             if (serializer->is_done()) return done();
                             self->writeSome(message, serializer, done);
                           });
  }

  /// A stream's client sends nothing more: a read that ends means it has gone.
  void watchForClose() {
    stream_.socket().async_read_some(
        net::buffer(discard_), net::bind_executor(stream_.get_executor(), [self = shared_from_this()](error_code ec, std::size_t) {
          if (ec) return self->close();
          self->watchForClose();
        }));
  }

  void nextPoll() {
    if (closed_) return;
    timer_.expires_after(interval_);
    timer_.async_wait([self = shared_from_this()](error_code ec) {
      if (ec || self->closed_) return;
      StreamStep step = self->poll_();
      if (step.data.empty()) return step.end ? self->close() : self->nextPoll();
      auto text = std::make_shared<std::string>(std::move(step.data));
      self->stream_.expires_after(duration(self->shared_->limits.write_timeout));
      net::async_write(self->stream_, net::buffer(*text), [self, text, end = step.end](error_code ec, std::size_t) {
        if (ec || end) return self->close();
        self->nextPoll();
      });
    });
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    timer_.cancel();
    poll_ = nullptr;
    error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream_.close();
  }

  beast::tcp_stream stream_;
  std::shared_ptr<HttpServer::Shared> shared_;
  std::string client_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  bool keep_alive_ = false;
  bool closed_ = false;
  net::steady_timer timer_;
  std::function<StreamStep()> poll_;
  std::chrono::milliseconds interval_{300};
  std::array<char, 4096> discard_{};
  std::size_t drained_ = 0;  ///< [bytes] discarded after a refusal
  static constexpr std::size_t kDrainBytes = 4 << 20;
};

void HttpReply::send(http::response<http::string_body> response) const {
  net::dispatch(session_->executor(), [s = session_, r = std::move(response)]() mutable { s->write(std::move(r)); });
}

void HttpReply::sendFile(http::response<http::file_body> response) const {
  net::dispatch(session_->executor(), [s = session_, r = std::move(response)]() mutable { s->write(std::move(r)); });
}

void HttpReply::stream(http::response<http::empty_body> header, std::function<StreamStep()> poll,
                       std::chrono::milliseconds interval) const {
  net::dispatch(session_->executor(), [s = session_, h = std::move(header), p = std::move(poll), interval]() mutable {
    s->stream(std::move(h), std::move(p), interval);
  });
}

net::any_io_executor HttpReply::executor() const { return session_->executor(); }

void HttpServer::onRefused(Refused refused) { shared_->refused = std::move(refused); }

HttpServer::HttpServer(HttpLimits limits, Handler handler)
    : shared_(std::make_shared<Shared>()), acceptor_(net::make_strand(ioc_)) {
  shared_->limits = limits;
  shared_->handler = std::move(handler);
}

HttpServer::~HttpServer() { stop(); }

void HttpServer::start(const std::string& bind, int port) {
  error_code ec;
  const auto address = net::ip::make_address(bind, ec);
  if (ec) throw std::runtime_error("cannot listen on " + bind + ": not an IP address");
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(port));
  acceptor_.open(endpoint.protocol(), ec);
  if (!ec) acceptor_.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) acceptor_.bind(endpoint, ec);
  if (!ec) acceptor_.listen(net::socket_base::max_listen_connections, ec);
  if (ec) throw std::runtime_error("cannot listen on " + bind + ":" + std::to_string(port) + ": " + ec.message());
  port_ = acceptor_.local_endpoint().port();
  accept();
  for (std::size_t i = 0; i < std::max<std::size_t>(1, shared_->limits.io_threads); ++i) {
    threads_.emplace_back([this] { ioc_.run(); });
  }
}

void HttpServer::stop() {
  if (threads_.empty()) return;
  ioc_.stop();
  for (auto& t : threads_) t.join();
  threads_.clear();
  error_code ignored;
  acceptor_.close(ignored);
}

void HttpServer::accept() {
  acceptor_.async_accept(net::make_strand(ioc_), [this](error_code ec, tcp::socket socket) {
    if (!acceptor_.is_open()) return;
    if (!ec) {
      error_code peer_error;
      const auto peer = socket.remote_endpoint(peer_error);
      std::string client = peer_error ? std::string("unknown") : peer.address().to_string();
      if (shared_->admit(client)) {
        std::make_shared<HttpSession>(std::move(socket), shared_, std::move(client))->start();
      } else {
        // Over a cap: a short 503, sent without waiting, and closed.
        static const std::string busy =
            cannedAnswer(503, "Service Unavailable", "too many connections from your address at once");
        error_code ignored;
        socket.non_blocking(true, ignored);
        socket.write_some(net::buffer(busy), ignored);
        socket.shutdown(tcp::socket::shutdown_both, ignored);
        socket.close(ignored);
      }
    }
    accept();
  });
}

}  // namespace collision_lab_web
