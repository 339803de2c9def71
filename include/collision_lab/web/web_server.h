// The class's web server (docs/web.md): pages, a JSON API and live event streams over
// cpp-httplib. It sends scenes to the lab node as InitialConditions (through `publish`),
// and shows what the RunBook gathers from the lab node's topics. ROS-free apart from the
// message types.
//
// Safety in a classroom: binds 127.0.0.1 unless told otherwise; with a class code set,
// POST /api/runs needs it (403); limits answer with an HTTP error and touch no one else:
// request body (413), bodies per scene (422, TOO_MANY_BODIES), runs per student per minute
// (429), concurrent event streams (503). Pages and files are served from a fixed list
// loaded at start; a bag is served only from its run's RunSummary.bag_path, never from a
// path in the URL.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/web/run_book.h"

namespace httplib {
class Server;
}

namespace collision_lab_web {

struct WebConfig {
  std::string bind = "127.0.0.1";
  int port = 8080;  ///< 0: any free port (WebServer::port() says which)
  std::string code;  ///< class code; empty: none needed
  std::size_t max_body_bytes = 1 << 20;  ///< [bytes] larger request bodies: 413
  std::size_t max_bodies = 10000;        ///< the lab node's ~max_bodies [1]
  std::size_t runs_per_minute = 10;      ///< per student [1]; more: 429
  std::size_t max_streams = 64;          ///< concurrent event streams [1]; more: 503
  /// How long POST /api/runs waits for the lab node's AcceptedRun or Rejected [s] (runs are
  /// served one at a time: a long run ahead delays the answer); then 504.
  double answer_timeout = 30.0;
  std::string web_root;       ///< folder of the pages (the package's web/)
  std::string chartjs_path;   ///< Debian's chart.min.js
  std::string scenario_file;  ///< the presets (config/scenarios.yaml)
};

class WebServer {
 public:
  /// publish: sends one input to the lab node; false when the lab node is not listening.
  using Publish = std::function<bool(const collision_lab::InitialConditions&)>;

  /// Loads the pages; throws std::runtime_error when one is missing.
  WebServer(RunBook& book, WebConfig config, Publish publish);
  ~WebServer();

  /// Binds and serves on a thread of its own; throws std::runtime_error when the address
  /// cannot be bound.
  void start();
  void stop();
  int port() const { return port_; }

 private:
  void routes();
  /// Seconds until `student` may send again; 0 (and the send counted) when allowed now.
  long admit(const std::string& student);

  RunBook& book_;
  WebConfig config_;
  Publish publish_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::map<std::string, std::string> files_;  ///< URL path -> content
  std::atomic<std::size_t> streams_{0};
  std::atomic<bool> stopping_{false};
  std::atomic<std::uint64_t> submissions_{0};
  std::mutex rate_mutex_;
  std::map<std::string, std::deque<std::chrono::steady_clock::time_point>> sends_;
};

}  // namespace collision_lab_web
