// A small asynchronous HTTP/1.1 server on Boost.Beast (issue 30): a fixed number of I/O
// threads serve every connection and every event stream; no thread waits for a client.
// What a slow or large client can hold is bounded per connection (a deadline for the whole
// header, one for the body, an idle keep-alive timeout, a write deadline per piece), per
// address and in total (connection caps), and per request (header and body size limits,
// whatever the transfer encoding: a chunked body counts against the same limit).
//
// Every answer, the server's own errors included, carries the security headers
// (kSecurityHeaders). ROS-free.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/http/empty_body.hpp>
#include <boost/beast/http/file_body.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>

namespace collision_lab_web {

namespace http = boost::beast::http;

struct HttpLimits {
  std::size_t io_threads = 2;          ///< [1] threads serving every connection
  double header_timeout = 10.0;        ///< [s] to receive a request's whole header
  double body_timeout = 30.0;          ///< [s] to receive its body once the header is in
  double idle_timeout = 5.0;           ///< [s] a kept-alive connection waits for the next header
  double write_timeout = 30.0;         ///< [s] to send one piece of an answer (a slow reader is cut)
  std::size_t max_body_bytes = 1 << 20;          ///< [bytes] larger bodies: 413, chunked included
  std::size_t max_header_bytes = 16 << 10;       ///< [bytes] larger headers: 431
  std::size_t max_connections_per_address = 32;  ///< [1] more from one address: 503 and closed
  std::size_t max_connections = 1024;            ///< [1] more in total: 503 and closed
};

/// Headers on every answer: no script, style or frame from elsewhere, no sniffing, no framing
/// of the pages, no Referer sent on.
extern const std::vector<std::pair<std::string, std::string>> kSecurityHeaders;

struct HttpRequest {
  http::request<http::string_body> message;
  std::string client;  ///< the peer's address, e.g. "127.0.0.1"
};

/// One step of an event stream: text to send (may be empty), and whether the stream ends
/// after it.
struct StreamStep {
  std::string data;
  bool end = false;
};

class HttpSession;

/// The answer to one request: exactly one of its calls, from any thread, once.
class HttpReply {
 public:
  explicit HttpReply(std::shared_ptr<HttpSession> session) : session_(std::move(session)) {}
  void send(http::response<http::string_body> response) const;
  /// Streams the file from disk piece by piece.
  void sendFile(http::response<http::file_body> response) const;
  /// Sends `header` (no length: the stream lasts until the connection closes), then calls
  /// `poll` every `interval` on the connection's strand and sends what it returns, until a
  /// step ends it or the client goes away. `poll` (and what it holds) is released then.
  void stream(http::response<http::empty_body> header, std::function<StreamStep()> poll,
              std::chrono::milliseconds interval) const;
  /// The connection's strand, for timers that belong to this request.
  boost::asio::any_io_executor executor() const;

 private:
  std::shared_ptr<HttpSession> session_;
};

class HttpServer {
 public:
  using Handler = std::function<void(HttpRequest request, HttpReply reply)>;

  /// handler: called on an I/O thread for each complete request; it must not block.
  HttpServer(HttpLimits limits, Handler handler);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// Told of each request the server refuses itself (413 too large, 431, 408), before the
  /// handler could see it: its client address, method, target and the status. Set before start.
  using Refused = std::function<void(const std::string& client, const std::string& method, const std::string& target,
                                     int status, const std::string& error)>;
  void onRefused(Refused refused);

  /// Binds (port 0: any free port) and starts the I/O threads; throws std::runtime_error
  /// when the address cannot be bound.
  void start(const std::string& bind, int port);
  /// Stops accepting and serving; joins the I/O threads.
  void stop();
  int port() const { return port_; }
  boost::asio::io_context& context() { return ioc_; }

  struct Shared;  ///< what sessions share with the server (limits, handler, counts)

 private:
  void accept();

  std::shared_ptr<Shared> shared_;
  boost::asio::io_context ioc_;
  boost::asio::ip::tcp::acceptor acceptor_;
  std::vector<std::thread> threads_;
  int port_ = 0;
};

}  // namespace collision_lab_web
