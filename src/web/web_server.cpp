#include "collision_lab/web/web_server.h"

#include <netinet/in.h>
#include <sys/socket.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "collision_lab/Rejected.h"
#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/bag_csv.h"
#include "collision_lab/ros/msg_conversion.h"
// Last: it includes <resolv.h>, whose macro _res breaks Eigen's headers included after it.
#include <httplib.h>

namespace collision_lab_web {

using nlohmann::json;

namespace {

/// A run_id in a URL: the node's own alphabet (InitialConditions.run_id). Anything else,
/// '/' and "%2F" included, is no run and gets a 404.
constexpr char kRunId[] = "([A-Za-z0-9_.\\-]+)";
/// A live stream sends the run at most this often, and a comment line when idle (so that a
/// closed tab is noticed and its slot freed).
constexpr auto kStreamInterval = std::chrono::milliseconds(300);
constexpr auto kStreamKeepAlive = std::chrono::seconds(10);
/// Presets of more bodies than this come without their lists (the form sends their name).
constexpr std::size_t kPresetSceneMaxBodies = 100;

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void sendJson(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

void sendError(httplib::Response& res, int status, const std::string& error, const std::string& field = {}) {
  json body = {{"error", error}};
  if (!field.empty()) body["field"] = field;
  sendJson(res, status, body);
}

/// A field's error: the field's name and what is wrong.
struct FieldError {
  std::string field, message;
};

double parseNumber(const json& value, const std::string& field) {
  if (value.is_number()) return value.get<double>();
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    if (text == "inf" || text == "+inf" || text == ".inf" || text == "wall") {
      return std::numeric_limits<double>::infinity();
    }
    if (text == "-inf" || text == "-.inf") return -std::numeric_limits<double>::infinity();
  }
  throw FieldError{field, field + " must be a number (or \"inf\" for a wall's mass), not " + value.dump()};
}

std::vector<double> parseList(const json& body, const std::string& name, bool required) {
  std::vector<double> out;
  if (!body.contains(name) || body[name].is_null()) {
    if (required) throw FieldError{name, name + " is required: one number per body"};
    return out;
  }
  const json& list = body[name];
  if (list.is_number()) return {parseNumber(list, name)};
  if (!list.is_array()) throw FieldError{name, name + " must be a list of numbers"};
  for (std::size_t i = 0; i < list.size(); ++i) out.push_back(parseNumber(list[i], name + "[" + std::to_string(i) + "]"));
  return out;
}

json rejectionJson(const collision_lab::Rejected& r) {
  return {{"rejected",
           {{"reason", r.reason}, {"reason_name", r.reason_name}, {"field", r.field}, {"message", r.message}}}};
}

std::string contentType(const std::string& path) {
  auto ends = [&](const std::string& tail) {
    return path.size() >= tail.size() && path.compare(path.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  return "text/html; charset=utf-8";
}

/// Debian's cpp-httplib 0.11 is built with a listen backlog of 5: thirty students
/// connecting at once overflow it, and some connections are dropped or reset. listen()
/// again on the bound socket (found by its port) sets a backlog of SOMAXCONN.
void widenBacklog(int port) {
  for (int fd = 0; fd < 1024; ++fd) {
    sockaddr_storage address{};
    socklen_t length = sizeof address;
    int listening = 0;
    socklen_t flag_length = sizeof listening;
    if (getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) continue;
    if (getsockopt(fd, SOL_SOCKET, SO_ACCEPTCONN, &listening, &flag_length) != 0 || !listening) continue;
    int bound = -1;
    if (address.ss_family == AF_INET) bound = ntohs(reinterpret_cast<sockaddr_in*>(&address)->sin_port);
    if (address.ss_family == AF_INET6) bound = ntohs(reinterpret_cast<sockaddr_in6*>(&address)->sin6_port);
    if (bound == port) ::listen(fd, SOMAXCONN);
  }
}

}  // namespace

WebServer::WebServer(RunBook& book, WebConfig config, Publish publish)
    : book_(book), config_(std::move(config)), publish_(std::move(publish)), server_(std::make_unique<httplib::Server>()) {
  for (const char* page : {"index.html", "run.html", "teacher.html", "app.js", "run.js", "style.css"}) {
    files_[std::string("/static/") + page] = readFile(config_.web_root + "/" + page);
  }
  files_["/static/chart.min.js"] = readFile(config_.chartjs_path);
  // Threads: one per event stream, plus room for the pages and the API meanwhile.
  const std::size_t threads = config_.max_streams + 16;
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  server_->set_payload_max_length(config_.max_body_bytes);
  server_->set_keep_alive_timeout(2);
  routes();
}

WebServer::~WebServer() { stop(); }

void WebServer::start() {
  port_ = config_.port == 0 ? server_->bind_to_any_port(config_.bind) : config_.port;
  if (port_ <= 0 || (config_.port != 0 && !server_->bind_to_port(config_.bind, config_.port))) {
    throw std::runtime_error("cannot listen on " + config_.bind + ":" + std::to_string(config_.port));
  }
  widenBacklog(port_);
  thread_ = std::thread([this] { server_->listen_after_bind(); });
}

void WebServer::stop() {
  stopping_ = true;
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

long WebServer::admit(const std::string& student) {
  using Clock = std::chrono::steady_clock;
  const auto now = Clock::now();
  std::lock_guard<std::mutex> lock(rate_mutex_);
  auto& sent = sends_[student];
  while (!sent.empty() && now - sent.front() >= std::chrono::minutes(1)) sent.pop_front();
  if (sent.size() >= config_.runs_per_minute) {
    const auto wait = std::chrono::minutes(1) - (now - sent.front());
    return std::max<long>(1, std::chrono::ceil<std::chrono::seconds>(wait).count());
  }
  sent.push_back(now);
  return 0;
}

void WebServer::routes() {
  httplib::Server& svr = *server_;
  auto page = [this](const std::string& name) {
    return [this, name](const httplib::Request&, httplib::Response& res) {
      res.set_content(files_.at("/static/" + name), contentType(name));
    };
  };
  svr.Get("/", page("index.html"));
  svr.Get("/teacher", page("teacher.html"));
  svr.Get("/static/([a-z.]+)", [this](const httplib::Request& req, httplib::Response& res) {
    auto it = files_.find(req.path);
    if (it == files_.end()) return sendError(res, 404, "no such file");
    res.set_header("Cache-Control", "max-age=3600");
    res.set_content(it->second, contentType(req.path));
  });
  // The run page: the run_id goes into the page escaped, in one attribute the scripts read.
  svr.Get(std::string("/runs/") + kRunId, [this](const httplib::Request& req, httplib::Response& res) {
    const std::string run_id = req.matches[1];
    if (!book_.has(run_id)) return sendError(res, 404, "no such run");
    std::string html = files_.at("/static/run.html");
    const std::string slot = "{{RUN_ID}}";
    for (auto at = html.find(slot); at != std::string::npos; at = html.find(slot, at)) {
      const std::string escaped = htmlEscape(run_id);
      html.replace(at, slot.size(), escaped);
      at += escaped.size();
    }
    res.set_content(html, "text/html; charset=utf-8");
  });

  svr.Get("/api/presets", [this](const httplib::Request&, httplib::Response& res) {
    json out = json::array();
    try {
      for (const auto& entry : collision_lab::io::loadScenes(config_.scenario_file)) {
        const auto& s = entry.scene;
        json item = {{"name", entry.name}, {"description", entry.description}, {"bodies", s.masses.size()}};
        if (s.masses.size() <= kPresetSceneMaxBodies) {
          json m = json::array();
          for (double x : s.masses) m.push_back(std::isinf(x) ? json("inf") : json(x));
          item["scene"] = {{"masses", m},
                           {"positions", s.positions},
                           {"velocities", s.velocities},
                           {"restitution", s.restitution},
                           {"max_collisions", entry.max_collisions}};
        }
        out.push_back(item);
      }
    } catch (const std::exception& e) {
      return sendError(res, 500, e.what());
    }
    sendJson(res, 200, out);
  });

  svr.Post("/api/runs", [this](const httplib::Request& req, httplib::Response& res) {
    json body;
    try {
      body = json::parse(req.body);
    } catch (const json::exception&) {
      return sendError(res, 400, "the body is not JSON");
    }
    if (!body.is_object()) return sendError(res, 400, "the body must be a JSON object");
    if (!config_.code.empty()) {
      std::string code = req.get_header_value("X-Class-Code");
      if (code.empty() && body.contains("code") && body["code"].is_string()) code = body["code"];
      if (code != config_.code) return sendError(res, 403, "a class code is needed to send a scene", "code");
    }
    if (!body.contains("student") || !body["student"].is_string() || body["student"].get<std::string>().empty()) {
      return sendError(res, 400, "student is required: your name", "student");
    }
    const std::string student = body["student"];
    collision_lab::InitialConditions input;
    try {
      if (body.contains("preset")) {
        if (!body["preset"].is_string()) throw FieldError{"preset", "preset must be a preset's name"};
        collision_lab::io::SceneEntry entry;
        try {
          entry = collision_lab::io::findScene(collision_lab::io::loadScenes(config_.scenario_file), body["preset"]);
        } catch (const collision_lab::io::ScenarioFileError& e) {
          throw FieldError{"preset", e.what()};
        }
        input = collision_lab_ros::toInitialConditions(entry.scene, collision_lab::core::RunMode::kFull,
                                                       entry.max_collisions);
      } else {
        input.masses = parseList(body, "masses", true);
        input.positions = parseList(body, "positions", true);
        input.velocities = parseList(body, "velocities", true);
        input.restitution = parseList(body, "restitution", false);
      }
      if (body.contains("max_collisions")) {
        const json& cap = body["max_collisions"];
        if (!cap.is_number_unsigned()) throw FieldError{"max_collisions", "max_collisions must be a whole number >= 0"};
        input.max_collisions = cap.get<std::uint64_t>();
      }
      if (body.contains("mode")) {
        const json& mode = body["mode"];
        if (!mode.is_number_unsigned() || mode.get<std::uint64_t>() > 255) throw FieldError{"mode", "mode must be 0, 1 or 2"};
        input.mode = static_cast<std::uint8_t>(mode.get<std::uint64_t>());
      }
      if (body.contains("run_id")) {
        if (!body["run_id"].is_string()) throw FieldError{"run_id", "run_id must be text"};
        input.run_id = body["run_id"];
      }
    } catch (const FieldError& e) {
      return sendError(res, 400, e.message, e.field);
    }
    if (input.masses.size() > config_.max_bodies) {
      collision_lab::Rejected r;
      r.reason = collision_lab::Rejected::TOO_MANY_BODIES;
      r.reason_name = "TOO_MANY_BODIES";
      r.field = "masses";
      r.message = std::to_string(input.masses.size()) + " bodies are more than this lab's max_bodies = " +
                  std::to_string(config_.max_bodies);
      return sendJson(res, 422, rejectionJson(r));
    }
    if (const long wait = admit(student)) {
      res.set_header("Retry-After", std::to_string(wait));
      return sendError(res, 429,
                       "at most " + std::to_string(config_.runs_per_minute) + " runs per student per minute; try again in " +
                           std::to_string(wait) + " s");
    }
    // Each input gets a run_id of its own to ask for, so that its answer is found.
    if (input.run_id.empty()) input.run_id = "run" + std::to_string(++submissions_);
    input.student = student;
    book_.expect(student, input.run_id);
    if (!publish_(input)) {
      book_.waitForAnswer(student, input.run_id, std::chrono::milliseconds(0));
      return sendError(res, 503, "the lab node is not listening; ask the teacher");
    }
    const auto timeout = std::chrono::milliseconds(static_cast<long>(config_.answer_timeout * 1000));
    const auto answer = book_.waitForAnswer(student, input.run_id, timeout);
    if (!answer) return sendError(res, 504, "the lab node did not answer in time; it may be busy with a long run");
    if (answer->rejected) return sendJson(res, 422, rejectionJson(*answer->rejected));
    sendJson(res, 201, {{"run_id", *answer->run_id}, {"url", "/runs/" + *answer->run_id}});
  });

  svr.Get("/api/runs", [this](const httplib::Request& req, httplib::Response& res) {
    std::optional<std::string> student;
    if (req.has_param("student")) student = req.get_param_value("student");
    res.set_content(book_.list(student), "application/json");
  });

  svr.Get(std::string("/api/runs/") + kRunId, [this](const httplib::Request& req, httplib::Response& res) {
    const auto run = book_.json(req.matches[1]);
    if (!run) return sendError(res, 404, "no such run");
    res.set_content(run->first, "application/json");
  });

  svr.Get(std::string("/api/runs/") + kRunId + "/events.csv", [this](const httplib::Request& req,
                                                                     httplib::Response& res) {
    const std::string run_id = req.matches[1];
    if (!book_.has(run_id)) return sendError(res, 404, "no such run");
    if (!book_.finished(run_id)) return sendError(res, 409, "the run is not finished yet");
    const std::string bag = book_.bagPath(run_id);
    if (bag.empty()) return sendError(res, 404, "the run was not recorded");
    try {
      res.set_content(eventsCsv(bag), "text/csv");
    } catch (const std::exception& e) {
      return sendError(res, 500, e.what());
    }
    res.set_header("Content-Disposition", "attachment; filename=\"" + run_id + "_events.csv\"");
  });

  // The bag: only the file its RunSummary names, and only when that file is <run_id>.bag.
  svr.Get(std::string("/api/runs/") + kRunId + "/bag", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string run_id = req.matches[1];
    const std::string bag = book_.bagPath(run_id);
    const std::string name = run_id + ".bag";
    if (bag.empty() || bag.size() < name.size() + 1 || bag.compare(bag.size() - name.size() - 1, std::string::npos, "/" + name) != 0) {
      return sendError(res, 404, "no recorded bag for this run");
    }
    try {
      res.set_content(readFile(bag), "application/octet-stream");
    } catch (const std::exception&) {
      return sendError(res, 404, "the bag is gone");
    }
    res.set_header("Content-Disposition", "attachment; filename=\"" + name + "\"");
  });

  // Server-Sent Events: the run as JSON (as GET /api/runs/<run_id>) whenever it changed,
  // at most every kStreamInterval; an event `final` ends the stream.
  svr.Get(std::string("/api/runs/") + kRunId + "/stream", [this](const httplib::Request& req,
                                                                 httplib::Response& res) {
    const std::string run_id = req.matches[1];
    if (!book_.has(run_id)) return sendError(res, 404, "no such run");
    if (streams_.fetch_add(1) >= config_.max_streams) {
      --streams_;
      return sendError(res, 503, "too many live streams at once; the page reloads the run instead");
    }
    res.set_header("Cache-Control", "no-cache");
    auto seen = std::make_shared<std::uint64_t>(0);
    auto last = std::make_shared<std::chrono::steady_clock::time_point>();
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, run_id, seen, last](std::size_t, httplib::DataSink& sink) {
          if (stopping_) {
            sink.done();
            return true;
          }
          const auto [version, finished] = book_.waitForChange(run_id, *seen, kStreamKeepAlive);
          if (version == *seen) {
            const std::string ping = ": ping\n\n";
            return sink.write(ping.data(), ping.size());
          }
          const auto since = std::chrono::steady_clock::now() - *last;
          if (!finished && since < kStreamInterval) std::this_thread::sleep_for(kStreamInterval - since);
          // Whether the run is final is read before its JSON (and after the pause above): a run
          // that finishes after this read has a newer version, which wakes the next call.
          const bool done = book_.finished(run_id);
          const auto run = book_.json(run_id);
          if (!run) return false;
          *seen = run->second;
          *last = std::chrono::steady_clock::now();
          const std::string event = std::string("event: ") + (done ? "final" : "run") + "\ndata: " + run->first + "\n\n";
          if (!sink.write(event.data(), event.size())) return false;
          if (done) sink.done();
          return true;
        },
        [this](bool) { --streams_; });
  });

  svr.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (res.body.empty()) {
      json body = {{"error", res.status == 413 ? "the request body is too large" : "not found"}};
      if (res.status != 404 && res.status != 413) body["error"] = "HTTP " + std::to_string(res.status);
      res.set_content(body.dump(), "application/json");
    }
  });
}

}  // namespace collision_lab_web
