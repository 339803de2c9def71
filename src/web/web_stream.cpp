// GET /api/runs/<run_id>/stream: a run's live event stream (Server-Sent Events).
#include "web_parts.h"

#include <memory>

#include <boost/asio/steady_timer.hpp>

namespace collision_lab_web {

namespace {

/// A live stream looks at its run this often, sends it when it changed, and a comment line
/// when idle this long.
constexpr auto kStreamInterval = std::chrono::milliseconds(300);
constexpr auto kStreamKeepAlive = std::chrono::seconds(10);

}  // namespace

// Server-Sent Events: the run as JSON (as GET /api/runs/<run_id>) whenever it changed, at
// most every kStreamInterval; an event `final` ends the stream, and an event `restart` when
// this server stops (stop(): the page goes on by polling, and the respawned server serves
// it). A timer per stream, no thread.
void WebServer::stream(const HttpRequest& request, const std::string& run_id, const HttpReply& reply) {
  if (!book_.has(run_id)) return reply.send(errorAnswer(request, 404, "no such run"));
  bool full = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t& mine = streams_by_address_[request.client];
    full = mine >= config_.max_streams_per_address || streams_ >= config_.max_streams;
    if (full && mine == 0) streams_by_address_.erase(request.client);
    if (!full) {
      ++mine;
      ++streams_;
    }
  }
  if (full) return reply.send(errorAnswer(request, 503, "too many live streams at once; the page reloads the run instead"));
  // The slot is freed when the stream's poll is released (stream ended or client gone).
  std::shared_ptr<void> slot(nullptr, [this, client = request.client](void*) {
    std::lock_guard<std::mutex> lock(mutex_);
    --streams_;
    if (--streams_by_address_[client] == 0) streams_by_address_.erase(client);
  });
  http::response<http::empty_body> header(http::status::ok, request.message.version());
  header.set(http::field::content_type, "text/event-stream");
  header.set(http::field::cache_control, "no-cache");
  auto seen = std::make_shared<std::uint64_t>(0);
  auto last = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
  reply.stream(
      std::move(header),
      [this, run_id, slot, seen, last]() -> StreamStep {
        if (stopping_) return {"event: restart\ndata: {\"reason\": \"the web server is restarting\"}\n\n", true};
        const auto now = std::chrono::steady_clock::now();
        const auto version = book_.waitForChange(run_id, *seen, std::chrono::milliseconds(0)).first;
        if (version == *seen) {
          if (now - *last < kStreamKeepAlive) return {};
          *last = now;
          return {": ping\n\n", false};
        }
        // Whether the run is final is read before its JSON: a run that finishes after this
        // read has a newer version, which the next poll sends.
        const bool done = book_.finished(run_id);
        const auto run = book_.json(run_id);
        if (!run) return {{}, true};
        *seen = run->second;
        *last = now;
        return {std::string("event: ") + (done ? "final" : "run") + "\ndata: " + run->first + "\n\n", done};
      },
      kStreamInterval);
}

}  // namespace collision_lab_web
