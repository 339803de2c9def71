#include "collision_lab/web/web_server.h"
#include "collision_lab/web/window_worldlines.h"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/thread_pool.hpp>
#include <nlohmann/json.hpp>

#include "collision_lab/Rejected.h"
#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/bag_csv.h"
#include "collision_lab/ros/bag_reading.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_view.h"
#include "collision_lab/ros/view_style.h"
#include "http_server.h"
#include "web_parts.h"

namespace collision_lab_web {

namespace {

/// At stop, open streams are given this long to send their `restart` event.
constexpr auto kStreamsEndWithin = std::chrono::seconds(1);
/// Presets of more bodies than this come without their lists (the form sends their name).
constexpr std::size_t kPresetSceneMaxBodies = 100;
/// An address's place held by a run whose end this node never saw is given back after this.
constexpr auto kForgetUnfinishedAfter = std::chrono::hours(1);

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::string contentType(const std::string& path) {
  auto ends = [&](const std::string& tail) {
    return path.size() >= tail.size() && path.compare(path.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  return "text/html; charset=utf-8";
}

/// A preset's scene as POST /api/runs takes it: the model and ring only when not the
/// defaults.
json presetSceneJson(const collision_lab::io::SceneEntry& entry) {
  const auto& s = entry.scene;
  json masses = json::array();
  for (double x : s.masses) masses.push_back(std::isinf(x) ? json("inf") : json(x));
  json scene = {{"masses", masses},
                {"positions", s.positions},
                {"velocities", s.velocities},
                {"restitution", s.restitution},
                {"max_collisions", entry.max_collisions}};
  const auto& model = s.restitution_model;
  using collision_lab::core::RestitutionModelKind;
  if (model.kind != RestitutionModelKind::kConstant) {
    scene["restitution_model"] = collision_lab::core::restitutionModelName(model.kind);
    switch (model.kind) {
      case RestitutionModelKind::kTc: scene["tc"] = model.tc; break;
      case RestitutionModelKind::kThreshold: scene["elastic_below"] = model.elastic_below; break;
      case RestitutionModelKind::kViscoelastic: scene["viscoelastic_speed"] = model.viscoelastic_speed; break;
      default: break;
    }
  }
  if (s.isRing()) scene["ring"] = s.ring;
  return scene;
}

/// The names this machine answers to: its hostname and every address of its interfaces.
std::set<std::string> machineNames() {
  std::set<std::string> names;
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) == 0 && host[0]) names.insert(lower(host));
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) == 0) {
    for (ifaddrs* a = list; a; a = a->ifa_next) {
      if (!a->ifa_addr) continue;
      char text[INET6_ADDRSTRLEN] = {};
      if (a->ifa_addr->sa_family == AF_INET) {
        inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(a->ifa_addr)->sin_addr, text, sizeof text);
      } else if (a->ifa_addr->sa_family == AF_INET6) {
        inet_ntop(AF_INET6, &reinterpret_cast<sockaddr_in6*>(a->ifa_addr)->sin6_addr, text, sizeof text);
      } else {
        continue;
      }
      names.insert(lower(text));
    }
    freeifaddrs(list);
  }
  return names;
}

}  // namespace

WebServer::WebServer(RunBook& book, WebConfig config, Publish publish, Cancel cancel, Log log)
    : book_(book),
      config_(std::move(config)),
      publish_(std::move(publish)),
      cancel_(std::move(cancel)),
      log_(std::move(log)),
      secrets_(config_.state_directory, config_.code, config_.teacher_code, config_.stop_tokens,
               [this](const std::string& line) { this->log(line); }),
      shares_(config_.unfinished_runs_per_address, kForgetUnfinishedAfter),
      blocking_(std::make_unique<BlockingPool>()) {
  for (const char* page : {"index.html", "run.html", "teacher.html", "login.html", "app.js", "run.js", "login.js", "style.css"}) {
    files_[std::string("/static/") + page] = readFile(config_.web_root + "/" + page);
  }
  files_["/static/chart.min.js"] = readFile(config_.chartjs_path);
  routes_ = makeRoutes();
  hosts_ = machineNames();
  for (const char* local : {"localhost", "127.0.0.1", "::1"}) hosts_.insert(local);
  if (config_.bind != "0.0.0.0" && config_.bind != "::") hosts_.insert(lower(config_.bind));
  for (const auto& host : config_.allowed_hosts) hosts_.insert(hostName(host));
  HttpLimits limits;
  limits.io_threads = config_.io_threads;
  limits.header_timeout = config_.header_timeout;
  limits.body_timeout = config_.body_timeout;
  limits.idle_timeout = config_.idle_timeout;
  limits.max_body_bytes = config_.max_body_bytes;
  limits.max_connections_per_address = config_.max_connections_per_address;
  limits.max_connections = config_.max_connections;
  server_ = std::make_unique<HttpServer>(limits, [this](HttpRequest request, HttpReply reply) {
    handle(std::move(request), std::move(reply));
  });
  server_->onRefused([this](const std::string&, const std::string& method, const std::string& target, int status,
                            const std::string& error) {
    if (method == "POST" && target.substr(0, target.find('?')) == "/api/runs") {
      refusedSend({}, "HTTP " + std::to_string(status), error);
    }
  });
}

WebServer::~WebServer() { stop(); }

void WebServer::start() {
  server_->start(config_.bind, config_.port);
  port_ = server_->port();
}

void WebServer::stop() {
  // Answers still awaited hold their connections: the book lets them go first.
  std::set<std::pair<std::string, std::string>> pending;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending.swap(pending_);
  }
  for (const auto& [student, requested] : pending) book_.forget(student, requested);
  // Open streams end with an event `restart` at their next poll, before the server closes.
  stopping_ = true;
  const auto deadline = std::chrono::steady_clock::now() + kStreamsEndWithin;
  while (streams_ > 0 && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (blocking_) {
    blocking_->pool.join();
    blocking_->readers.join();
    blocking_->exports.join();
  }
  if (server_) server_->stop();
}

void WebServer::setQueue(const collision_lab::RunQueue& queue) {
  json runs = json::array();
  for (const auto& r : queue.runs) {
    runs.push_back({{"run_id", r.run_id},
                    {"student", r.student},
                    {"lane", r.lane},
                    {"running", r.running != 0},
                    {"predicted_collisions", r.predicted_collisions},
                    {"body_count", r.body_count}});
  }
  const json out = {{"workers", queue.workers},
                    {"short_lane_workers", queue.short_lane_workers},
                    {"stamp", queue.header.stamp.toSec()},
                    {"runs", runs}};
  std::lock_guard<std::mutex> lock(mutex_);
  queue_json_ = out.dump();
}

void WebServer::log(const std::string& line) const {
  if (!log_) return;
  std::string shown = line.substr(0, kLogLineBytes);
  for (char& c : shown) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  log_(shown);
}

void WebServer::handle(HttpRequest request, HttpReply reply) {
  const auto& m = request.message;
  const std::string target(m.target());
  const std::string path = target.substr(0, target.find('?'));
  const std::string host(m[http::field::host]);
  // DNS rebinding: a page of another site whose name now points here says so in Host.
  if (!host.empty() && !hostAllowed(host)) {
    log("refused " + request.client + ": foreign Host header");
    return reply.send(errorAnswer(request, 421, "this server does not serve that host name"));
  }
  if (m.method() == http::verb::post) {
    const std::string origin(m[http::field::origin]);
    const std::string fetch_site(m["Sec-Fetch-Site"]);
    if ((!origin.empty() && !originAllowed(origin, host)) || fetch_site == "cross-site") {
      log("refused " + request.client + ": POST from another site");
      return reply.send(errorAnswer(request, 403, "requests from other sites are not accepted"));
    }
    // Only JSON, whatever its size (the body limit applies to every type alike): a form of
    // another site can send text/plain or a form encoding without asking first, not JSON.
    const std::string type(m[http::field::content_type]);
    if (!m.body().empty() && lower(type).rfind("application/json", 0) != 0) {
      const std::string error = "send the body as JSON with the header Content-Type: application/json (curl: -H "
                                "'Content-Type: application/json'); this request's Content-Type: " +
                                (type.empty() ? std::string("none") : printableExcerpt(type, 80));
      if (path == "/api/runs") refusedSend(m.body(), "HTTP 415", error);
      return reply.send(errorAnswer(request, 415, error));
    }
  }

  // Codes: a presented code that is wrong counts against the address.
  Access access;
  access.student = config_.code.empty();
  access.teacher = config_.teacher_code.empty();
  std::vector<std::string> presented;
  const std::string class_header(m["X-Class-Code"]), teacher_header(m["X-Teacher-Code"]);
  if (!class_header.empty()) presented.push_back(class_header);
  if (!teacher_header.empty()) presented.push_back(teacher_header);
  if (m.method() == http::verb::post && path == "/api/runs" && m.body().size() <= config_.max_body_bytes) {
    const json body = json::parse(m.body(), nullptr, false);
    if (body.is_object() && body.contains("code") && body["code"].is_string()) presented.push_back(body["code"]);
  }
  if (!presented.empty()) {
    if (const long wait = lockedOut(request.client)) {
      Response res = errorAnswer(request, 429, "too many wrong codes from your address; try again in " + std::to_string(wait) + " s", "code");
      res.set(http::field::retry_after, std::to_string(wait));
      return reply.send(std::move(res));
    }
    for (const auto& code : presented) {
      const bool is_class = !config_.code.empty() && sameSecret(code, config_.code);
      const bool is_teacher = !config_.teacher_code.empty() && sameSecret(code, config_.teacher_code);
      if (!is_class && !is_teacher && (!config_.code.empty() || !config_.teacher_code.empty())) {
        return refuseWrongCode(request, "", reply);
      }
      access.student = access.student || is_class || is_teacher;
      access.teacher = access.teacher || is_teacher;
    }
  }
  access.student = access.student || sameSecret(cookie(request, kClassCookie), secrets_.classCookie());
  if (sameSecret(cookie(request, kTeacherCookie), secrets_.teacherCookie())) access.student = access.teacher = true;

  const bool open_route = path == "/login" || path == "/api/login" || path == "/static/style.css" || path == "/static/login.js";
  if (!access.student && !open_route) {
    if (m.method() == http::verb::get && path.rfind("/api/", 0) != 0 && path.rfind("/static/", 0) != 0) {
      return reply.send(redirect(request, "/login"));
    }
    return reply.send(errorAnswer(request, 403, "the class code is needed: log in on /login, or send the header X-Class-Code", "code"));
  }
  route(request, access, reply);
}

/// What a route's handler is given: the request, what it may do, the path's captures
/// (match[1], ...), the query string and where the answer goes.
struct WebServer::RouteCall {
  const HttpRequest& request;
  const Access& access;
  const std::smatch& match;
  const std::string& query;
  const HttpReply& reply;
};

std::vector<WebServer::Route> WebServer::makeRoutes() {
  using V = http::verb;
  const auto page = [this](const std::string& name) {
    return [this, name](const RouteCall& c) {
      c.reply.send(answer(c.request, http::status::ok, files_.at("/static/" + name), contentType(name)));
    };
  };
  const std::string run = "/api/runs/" + kRunId;
  return {
      {V::get, "/", page("index.html")},
      {V::get, "/login", page("login.html")},
      {V::get, "/teacher",
       [this, teacher = page("teacher.html")](const RouteCall& c) {
         if (!c.access.teacher) return c.reply.send(redirect(c.request, "/login?teacher=1"));
         teacher(c);
       }},
      {V::get, "/static/.*", [this](const RouteCall& c) { sendStatic(c.request, c.reply); }},
      {V::get, "/runs/" + kRunId, [this](const RouteCall& c) { sendRunPage(c.request, c.match[1], c.reply); }},
      {V::post, "/api/login", [this](const RouteCall& c) { login(c.request, c.reply); }},
      {V::get, "/api/presets", [this](const RouteCall& c) { sendPresets(c.request, c.reply); }},
      {V::get, "/api/body_colours",
       [](const RouteCall& c) {
         // rviz's palette, body i in palette[i % size] (RunView's colours), for the form.
         json palette = json::array();
         for (std::size_t i = 0; i < collision_lab_ros::markers::layout::kPaletteSize; ++i) {
           palette.push_back(collision_lab_ros::bodyColourHex(i));
         }
         c.reply.send(jsonAnswer(c.request, 200, json{{"palette", palette}}));
       }},
      {V::post, "/api/runs", [this](const RouteCall& c) { postRun(c.request, c.reply); }},
      {V::get, "/api/runs", [this](const RouteCall& c) { sendRunList(c.request, c.query, c.reply); }},
      {V::get, "/api/rejections",
       [this](const RouteCall& c) {
         if (!c.access.teacher) {
           return c.reply.send(errorAnswer(c.request, 403, "only the teacher sees the rejected inputs", "code"));
         }
         c.reply.send(answer(c.request, http::status::ok, rejectionsJson(queryParam(c.query, "student")), "application/json"));
       }},
      {V::get, "/api/queue", [this](const RouteCall& c) { sendQueue(c.request, c.reply); }},
      {V::post, "/api/students/([A-Za-z0-9_-]{1,64})/stop",
       [this](const RouteCall& c) { stopStudent(c.request, c.match[1], c.access, c.reply); }},
      {V::get, run, [this](const RouteCall& c) { sendRun(c.request, c.match[1], c.reply); }},
      {V::post, run + "/stop", [this](const RouteCall& c) { stopRun(c.request, c.match[1], c.access, c.reply); }},
      {V::get, run + "/events\\.csv", [this](const RouteCall& c) { sendEventsCsv(c.request, c.match[1], c.reply); }},
      {V::get, run + "/table\\.csv", [this](const RouteCall& c) { sendClassTable(c.request, c.match[1], c.reply); }},
      {V::get, run + "/worldlines", [this](const RouteCall& c) { sendWindow(c.request, c.match[1], c.query, c.reply); }},
      {V::get, run + "/bag", [this](const RouteCall& c) { sendBag(c.request, c.match[1], c.reply); }},
      {V::get, run + "/stream", [this](const RouteCall& c) { stream(c.request, c.match[1], c.reply); }},
  };
}

void WebServer::route(const HttpRequest& request, const Access& access, const HttpReply& reply) {
  const auto& m = request.message;
  if (m.method() != http::verb::get && m.method() != http::verb::post) {
    Response res = errorAnswer(request, 405, "only GET and POST are served");
    res.set(http::field::allow, "GET, POST");
    return reply.send(std::move(res));
  }
  const std::string target(m.target());
  const auto question = target.find('?');
  const std::string path = target.substr(0, question);
  const std::string query = question == std::string::npos ? std::string() : target.substr(question + 1);
  std::smatch match;
  for (const Route& r : routes_) {
    if (r.method == m.method() && std::regex_match(path, match, r.path)) {
      return r.handle(RouteCall{request, access, match, query, reply});
    }
  }
  reply.send(errorAnswer(request, 404, "not found"));
}

void WebServer::sendStatic(const HttpRequest& request, const HttpReply& reply) {
  const std::string target(request.message.target());
  const auto it = files_.find(target.substr(0, target.find('?')));
  if (it == files_.end()) return reply.send(errorAnswer(request, 404, "no such file"));
  Response res = answer(request, http::status::ok, it->second, contentType(it->first));
  res.set(http::field::cache_control, "max-age=3600");
  reply.send(std::move(res));
}

// The run page: the run_id goes into the page escaped, in one attribute the scripts read.
void WebServer::sendRunPage(const HttpRequest& request, const std::string& run_id, const HttpReply& reply) {
  if (!book_.has(run_id)) return reply.send(errorAnswer(request, 404, "no such run"));
  std::string html = files_.at("/static/run.html");
  const std::string slot = "{{RUN_ID}}";
  const std::string escaped = htmlEscape(run_id);
  for (auto at = html.find(slot); at != std::string::npos; at = html.find(slot, at)) {
    html.replace(at, slot.size(), escaped);
    at += escaped.size();
  }
  reply.send(answer(request, http::status::ok, std::move(html), "text/html; charset=utf-8"));
}

// GET /api/presets: each preset's name, description and size, and its scene as POST
// /api/runs takes it (presets of at most kPresetSceneMaxBodies bodies).
void WebServer::sendPresets(const HttpRequest& request, const HttpReply& reply) {
  json out = json::array();
  try {
    for (const auto& entry : collision_lab::io::loadScenes(config_.scenario_file)) {
      const auto& s = entry.scene;
      json item = {{"name", entry.name}, {"description", entry.description}, {"bodies", s.masses.size()}};
      if (s.masses.size() <= kPresetSceneMaxBodies) item["scene"] = presetSceneJson(entry);
      out.push_back(item);
    }
  } catch (const std::exception& e) {
    return reply.send(errorAnswer(request, 500, e.what()));
  }
  reply.send(jsonAnswer(request, 200, out));
}

// GET /api/runs[?student=NAME][&offset=K][&limit=N]: the runs, oldest first, or a page of
// them; X-Total-Count gives the whole list's length. Read on a reader thread.
void WebServer::sendRunList(const HttpRequest& request, const std::string& query, const HttpReply& reply) {
  RunBook::ListPage page;
  for (const auto& [name, value] : {std::pair<const char*, std::size_t*>{"offset", &page.offset}, {"limit", &page.limit}}) {
    const auto text = queryParam(query, name);
    if (!text) continue;
    if (text->empty() || text->size() > 9 || text->find_first_not_of("0123456789") != std::string::npos) {
      return reply.send(errorAnswer(request, 400, std::string(name) + " must be a whole number", name));
    }
    *value = std::stoul(*text);
  }
  boost::asio::post(blocking_->readers, [this, request, reply, page, student = queryParam(query, "student")]() mutable {
    std::size_t total = 0;
    page.total = &total;
    Response res = answer(request, http::status::ok, book_.list(student, page), "application/json");
    res.set("X-Total-Count", std::to_string(total));
    reply.send(std::move(res));
  });
}

void WebServer::sendQueue(const HttpRequest& request, const HttpReply& reply) {
  std::string body;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    body = queue_json_;
  }
  if (body.empty()) body = json{{"workers", 0}, {"short_lane_workers", 0}, {"stamp", 0.0}, {"runs", json::array()}}.dump();
  reply.send(answer(request, http::status::ok, std::move(body), "application/json"));
}

// GET /api/runs/<run_id>: held runs at once, others read back from their bag on a reader.
void WebServer::sendRun(const HttpRequest& request, const std::string& run_id, const HttpReply& reply) {
  const auto send = [this, request, reply, run_id] {
    const auto run = book_.json(run_id);
    if (!run) return reply.send(errorAnswer(request, 404, "no such run"));
    reply.send(answer(request, http::status::ok, run->first, "application/json"));
  };
  if (book_.resident(run_id)) return send();
  boost::asio::post(blocking_->readers, send);
}

std::string WebServer::rejectionsJson(const std::optional<std::string>& student) const {
  json rows = json::parse(book_.rejections(student), nullptr, false);
  if (!rows.is_array()) rows = json::array();
  // A numbered send's rejection is found by its student and run_id, answered within this
  // long of the index's stamp [s]; a typed run_id like it, long after, stays shown.
  constexpr double kSameSend = 30;
  std::lock_guard<std::mutex> lock(mutex_);
  for (json& row : rows) {
    row["by"] = "lab node";
    for (const Refusal& r : numbered_rejections_) {
      if (r.student == row.value("student", "") && r.run_id == row.value("run_id", "") &&
          std::abs(r.at - row.value("at", 0.0)) < kSameSend) {
        row["run_id"] = "";
        break;
      }
    }
  }
  for (const Refusal& r : refusals_) {
    if (student && r.student != *student) continue;
    rows.push_back({{"at", r.at}, {"student", r.student}, {"run_id", r.run_id}, {"reason_name", r.reason_name},
                    {"field", r.field}, {"message", r.message}, {"by", "web node"}});
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const json& a, const json& b) { return a.value("at", 0.0) > b.value("at", 0.0); });
  return rows.dump();
}

}  // namespace collision_lab_web
