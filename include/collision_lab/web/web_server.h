// The class's web server (docs/web.md): pages, a JSON API and live event streams on an
// asynchronous HTTP server (Boost.Beast, src/web/http_server.h): a few I/O threads serve
// every connection and stream, and no request holds a thread while it waits. It sends
// scenes to the lab node as InitialConditions (through `publish`), stops runs through the
// lab node's ~cancel (through `cancel`), and shows what the RunBook gathers from the lab
// node's topics. ROS-free apart from the message types.
//
// Safety in a classroom: binds 127.0.0.1 unless told otherwise. Per connection: header and
// body deadlines, an idle timeout, header and body size limits whatever the transfer
// encoding (413); connections per address and in total are capped (503). With a class code
// set, every route needs it (a cookie after POST /api/login, or the header X-Class-Code);
// a teacher code guards /teacher and stopping others' runs. Wrong codes are counted per
// client address: 429, then a lockout that ends by itself. POSTs with a foreign Origin are
// 403; a Host that is not one of the lab's names is 421 (DNS rebinding). Every answer
// carries the security headers. Runs per student and per address per minute (429),
// bodies per scene (422, TOO_MANY_BODIES), concurrent event streams (503). Pages and files
// are served from a fixed list loaded at start; a bag is served only from its run's
// RunSummary.bag_path, never from a path in the URL.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <boost/beast/http/verb.hpp>
#include <nlohmann/json_fwd.hpp>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/RunQueue.h"
#include "collision_lab/service/address_share.h"
#include "collision_lab/web/run_book.h"
#include "collision_lab/web/web_secrets.h"

namespace collision_lab_web {

class HttpServer;
class HttpReply;
struct HttpRequest;
struct BlockingPool;

struct WebConfig {
  std::string bind = "127.0.0.1";
  int port = 8080;  ///< 0: any free port (WebServer::port() says which)
  std::string code;          ///< class code; empty: none needed
  std::string teacher_code;  ///< teacher code (the teacher page, stopping any run); empty: none needed
  /// More names the lab is reached by (Host header), besides bind, localhost, 127.0.0.1,
  /// the machine's hostname and its addresses.
  std::vector<std::string> allowed_hosts;
  std::size_t max_body_bytes = 1 << 20;  ///< [bytes] larger request bodies: 413 (chunked too)
  std::size_t max_bodies = 10000;        ///< the lab node's ~max_bodies [1]
  std::size_t runs_per_minute = 10;      ///< per student [1]; more: 429
  std::size_t runs_per_minute_per_address = 30;  ///< per client address [1]; more: 429
  /// per student name at an address per hour [1]; more: 429 (a lesson's ceiling: a script
  /// sending all afternoon stops here)
  std::size_t runs_per_hour = 200;
  /// Runs of one client address sent and not yet finished (queued or running), whatever the
  /// names [1]; more: 429 until one ends. 0: no cap.
  std::size_t unfinished_runs_per_address = 6;
  std::size_t max_streams = 64;          ///< concurrent event streams [1]; more: 503
  std::size_t max_streams_per_address = 8;  ///< concurrent event streams of one client address [1]; more: 503
  std::size_t code_attempts = 5;         ///< wrong codes per address per minute [1] before the lockout
  /// Wrong codes per minute from all addresses together [1]: once spent, a single wrong code
  /// locks its address out for code_lockout, so each address guesses once per lockout
  /// instead of code_attempts times a minute.
  std::size_t code_attempts_total = 50;
  double code_lockout = 60.0;            ///< [s] an address is locked out after too many wrong codes
  /// How long POST /api/runs waits for the lab node's AcceptedRun or Rejected [s]; then 503.
  double answer_timeout = 10.0;
  std::size_t io_threads = 2;            ///< [1] threads serving every connection
  double header_timeout = 10.0;          ///< [s] to receive a request's whole header
  double body_timeout = 30.0;            ///< [s] to receive a request's body
  double idle_timeout = 5.0;             ///< [s] a kept-alive connection may stay idle
  std::size_t max_connections_per_address = 32;  ///< [1] open connections per client address
  std::size_t max_connections = 1024;    ///< [1] open connections in total
  std::size_t stop_tokens = 4096;        ///< [1] runs whose stop_token is remembered (newest)
  /// Where the cookie secrets and the stop tokens' hashes are kept across restarts (the web
  /// node's ~bag_directory; WebSecrets); empty: this start only.
  std::string state_directory;
  std::string web_root;       ///< folder of the pages (the package's web/)
  std::string chartjs_path;   ///< Debian's chart.min.js
  std::string scenario_file;  ///< the presets (config/scenarios.yaml)
};

/// The lab node's answer to a cancel (srv/Cancel.srv).
struct CancelAnswer {
  bool ok = false;
  std::string message;
};

class WebServer {
 public:
  /// publish: sends one input to the lab node; false when the lab node is not listening.
  using Publish = std::function<bool(const collision_lab::InitialConditions&)>;
  /// cancel: asks the lab node to stop run_id for requested_by; nullopt when the lab node
  /// cannot be reached. May block: it is called on a thread of its own, never an I/O one.
  using Cancel = std::function<std::optional<CancelAnswer>(const std::string& run_id, const std::string& requested_by)>;
  /// log: one short line about a refused request (at most kLogLineBytes).
  using Log = std::function<void(const std::string&)>;
  static constexpr std::size_t kLogLineBytes = 200;

  /// Loads the pages; throws std::runtime_error when one is missing.
  WebServer(RunBook& book, WebConfig config, Publish publish, Cancel cancel = {}, Log log = {});
  ~WebServer();

  /// Binds and serves on its I/O threads; throws std::runtime_error when the address cannot
  /// be bound.
  void start();
  void stop();
  int port() const { return port_; }
  /// The lab node's latest queue (its latched `run_queue`), served by GET /api/queue.
  void setQueue(const collision_lab::RunQueue& queue);

  struct Access;  ///< what a request may do (its codes)

 private:
  void handle(HttpRequest request, HttpReply reply);
  /// The route table: {method, path pattern, handler}; the first route whose method and
  /// pattern match a request answers it, and a request no route takes is 404.
  struct RouteCall;
  struct Route {
    Route(boost::beast::http::verb method, const std::string& pattern, std::function<void(const RouteCall&)> handle)
        : method(method), path(pattern), handle(std::move(handle)) {}
    boost::beast::http::verb method;
    std::regex path;
    std::function<void(const RouteCall&)> handle;
  };
  std::vector<Route> makeRoutes();
  void route(const HttpRequest& request, const Access& access, const HttpReply& reply);
  void sendStatic(const HttpRequest& request, const HttpReply& reply);
  void sendRunPage(const HttpRequest& request, const std::string& run_id, const HttpReply& reply);
  void sendPresets(const HttpRequest& request, const HttpReply& reply);
  void sendQueue(const HttpRequest& request, const HttpReply& reply);
  void sendRunList(const HttpRequest& request, const std::string& query, const HttpReply& reply);
  void sendRun(const HttpRequest& request, const std::string& run_id, const HttpReply& reply);
  void postRun(const HttpRequest& request, const HttpReply& reply);
  struct Refuse;  ///< answers a refused send (web_post.cpp)
  collision_lab::InitialConditions sceneOfSend(const nlohmann::json& body) const;
  bool admitSend(const HttpRequest& request, const collision_lab::InitialConditions& input, const std::string& student,
                 const Refuse& refuse, const HttpReply& reply);
  void sendToLab(const HttpRequest& request, const HttpReply& reply, collision_lab::InitialConditions input,
                 const Refuse& refuse);
  void stopRun(const HttpRequest& request, const std::string& run_id, const Access& access, const HttpReply& reply);
  /// POST /api/students/<student>/stop (the teacher): every queued or running run of student.
  void stopStudent(const HttpRequest& request, const std::string& student, const Access& access, const HttpReply& reply);
  void login(const HttpRequest& request, const HttpReply& reply);
  /// A wrong class or teacher code (`where`: "at login " or ""): logged and counted, then
  /// 403, or 429 with Retry-After once the address is locked out.
  void refuseWrongCode(const HttpRequest& request, const std::string& where, const HttpReply& reply);
  /// A file made once from a finished run's bag, kept beside the bag as <run_id>_<name> and
  /// sent. make(bag, folder) writes it into a temporary folder and returns its path there,
  /// or the empty string and, in why, the 404 text when the run has no such file.
  using MakeFromBag = std::function<std::string(const std::string& bag, const std::string& folder, std::string& why)>;
  void sendMadeFromBag(const HttpRequest& request, const std::string& run_id, const std::string& name,
                       MakeFromBag make, const HttpReply& reply);
  /// One file made from a bag at a time per address: true and the address noted, or false
  /// and answered 429. endExport releases it.
  bool startExport(const HttpRequest& request, const HttpReply& reply);
  void endExport(const std::string& client);
  void sendEventsCsv(const HttpRequest& request, const std::string& run_id, const HttpReply& reply);
  void sendClassTable(const HttpRequest& request, const std::string& run_id, const HttpReply& reply);
  void sendWindow(const HttpRequest& request, const std::string& run_id, const std::string& query,
                  const HttpReply& reply);
  void sendBag(const HttpRequest& request, const std::string& run_id, const HttpReply& reply);
  void stream(const HttpRequest& request, const std::string& run_id, const HttpReply& reply);
  /// Seconds until `key` may send again under `limit` per `window`; 0 when now, and then
  /// the send is counted unless `count` is false (a look before the other limits agree).
  long admit(const std::string& key, std::size_t limit, std::chrono::seconds window = std::chrono::minutes(1),
             bool count = true);
  /// Seconds the address is still locked out for wrong codes; 0 when it is not.
  long lockedOut(const std::string& client);
  /// Counts a wrong code from `client`: seconds of lockout when it is now locked out, else 0.
  long wrongCode(const std::string& client);
  bool hostAllowed(const std::string& host) const;
  bool originAllowed(const std::string& origin, const std::string& host) const;
  void log(const std::string& line) const;
  /// Notes a send to POST /api/runs that this node refused itself (400, 413, 415, 422, 429),
  /// with the student and run_id its body named, when it could be read.
  void refusedSend(const std::string& body, const std::string& reason_name, const std::string& error,
                   const std::string& field = {});
  /// GET /api/rejections: the lab node's rejections (the run index) and this node's own
  /// refusals, newest first; a run_id this node numbered itself is shown empty.
  std::string rejectionsJson(const std::optional<std::string>& student) const;

  RunBook& book_;
  WebConfig config_;
  Publish publish_;
  Cancel cancel_;
  Log log_;
  int port_ = 0;
  std::map<std::string, std::string> files_;  ///< URL path -> content
  std::set<std::string> hosts_;               ///< names the lab serves (Host without port)
  WebSecrets secrets_;  ///< the cookies' secrets and the stop tokens, kept across restarts
  std::atomic<std::size_t> streams_{0};
  std::atomic<bool> stopping_{false};  ///< stop() began: streams end with `restart`
  collision_lab::service::AddressShare shares_;  ///< unfinished_runs_per_address
  mutable std::mutex mutex_;  ///< guards everything below
  std::map<std::string, std::deque<std::chrono::steady_clock::time_point>> sends_;
  std::map<std::string, std::deque<std::chrono::steady_clock::time_point>> hourly_sends_;  ///< windows over a minute
  std::map<std::string, std::deque<std::chrono::steady_clock::time_point>> wrong_codes_;
  std::deque<std::chrono::steady_clock::time_point> wrong_codes_total_;  ///< of the last minute, every address
  std::map<std::string, std::size_t> streams_by_address_;  ///< live streams per client address (no zero kept)
  std::map<std::string, std::chrono::steady_clock::time_point> locked_until_;
  std::set<std::string> exporting_;  ///< addresses with a file being made from a bag
  std::set<std::pair<std::string, std::string>> pending_;  ///< (student, requested) POSTs awaiting an answer
  /// student -> the highest n of the runs "<student>.run<n>" asked for or served [1]. The lab
  /// node serves a taken "run<n>" as the next free number, so numbers stay per student and
  /// unique across restarts of either node.
  std::map<std::string, std::uint64_t> runs_numbered_;
  /// A refused send as the teacher page lists it; `at` [s since the epoch].
  struct Refusal {
    double at = 0;
    std::string student, run_id, reason_name, field, message;
  };
  /// This node's own refusals of sends, newest last, at most kRefusalsKept: in memory only
  /// (the run index is the lab node's file; these never reached the lab node).
  std::deque<Refusal> refusals_;
  /// The lab node's rejections of sends this node numbered itself (no run_id typed), newest
  /// last, at most kRefusalsKept: their index rows show no run_id asked for.
  std::deque<Refusal> numbered_rejections_;
  static constexpr std::size_t kRefusalsKept = 1000;
  std::string queue_json_;
  std::unique_ptr<BlockingPool> blocking_;  ///< cancel calls and CSV conversions
  std::unique_ptr<HttpServer> server_;
  std::vector<Route> routes_;  ///< after everything its handlers use
};

}  // namespace collision_lab_web
