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

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/thread_pool.hpp>
#include <nlohmann/json.hpp>

#include "collision_lab/Rejected.h"
#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/bag_csv.h"
#include "collision_lab/ros/bag_reading.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/markers/layout.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_view.h"
#include "http_server.h"

namespace collision_lab_web {

using nlohmann::json;
namespace fs = std::filesystem;

/// Work kept off the I/O threads: `pool` for cancel calls and CSV conversions, `readers`
/// for the run list (the index) and runs read back from their bags. Each bounds how many
/// run at once; the I/O threads serve pages and sends meanwhile.
struct BlockingPool {
  boost::asio::thread_pool pool{2};
  boost::asio::thread_pool readers{2};
};

struct WebServer::Access {
  bool student = false;  ///< the class code was given (or none is needed)
  bool teacher = false;  ///< the teacher code was given (or none is needed)
};

namespace {

using Response = http::response<http::string_body>;

/// A run_id in a URL: the node's own alphabet (InitialConditions.run_id). Anything else,
/// '/' and "%2F" included, is no run and gets a 404.
const std::string kRunId = "([A-Za-z0-9_.\\-]+)";
/// A live stream looks at its run this often, sends it when it changed, and a comment line
/// when idle this long.
constexpr auto kStreamInterval = std::chrono::milliseconds(300);
constexpr auto kStreamKeepAlive = std::chrono::seconds(10);
/// Presets of more bodies than this come without their lists (the form sends their name).
constexpr std::size_t kPresetSceneMaxBodies = 100;
/// The class table's widest run: two columns per body, a row per event.
constexpr std::size_t kClassTableMaxBodies = 64;
/// A time window's x-t diagram: at most this many bodies, and vertices per body.
constexpr std::size_t kWindowMaxBodies = 64;
constexpr std::size_t kWindowVertices = 2048;
constexpr char kClassCookie[] = "collision_lab_class";
constexpr char kTeacherCookie[] = "collision_lab_teacher";
/// [s] a login lasts: a school day.
constexpr int kCookieSeconds = 12 * 3600;
/// Longest run_id the lab node takes [characters].
constexpr std::size_t kMaxRunIdLength = 128;
/// An address's place held by a run whose end this node never saw is given back after this.
constexpr auto kForgetUnfinishedAfter = std::chrono::hours(1);
constexpr int kUnfinishedRetryAfter = 5;  ///< [s] Retry-After of a 429 for unfinished runs

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

/// n of a run served as "<student>.run<n>" (the student's n-th run); nullopt for any other id.
std::optional<std::uint64_t> runNumber(const std::string& run_id, const std::string& student) {
  const std::string prefix = student + ".run";
  if (run_id.size() <= prefix.size() || run_id.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  const std::string digits = run_id.substr(prefix.size());
  if (digits.size() > 18 || digits.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return std::stoull(digits);
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

/// "name:port", "[v6]:port" or "name" -> the name, lower case, without brackets.
std::string hostName(const std::string& host) {
  if (!host.empty() && host.front() == '[') return lower(host.substr(1, host.find(']') - 1));
  const auto colon = host.find(':');
  if (colon != std::string::npos && host.find(':', colon + 1) == std::string::npos) return lower(host.substr(0, colon));
  return lower(host);
}

std::string cookie(const HttpRequest& request, const std::string& name) {
  const std::string header(request.message[http::field::cookie]);
  std::size_t at = 0;
  while (at < header.size()) {
    const auto end = std::min(header.find(';', at), header.size());
    std::string pair = header.substr(at, end - at);
    pair.erase(0, pair.find_first_not_of(' '));
    const auto eq = pair.find('=');
    if (eq != std::string::npos && pair.substr(0, eq) == name) return pair.substr(eq + 1);
    at = end + 1;
  }
  return {};
}

std::string urlDecode(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '+') {
      out += ' ';
    } else if (text[i] == '%' && i + 2 < text.size() && std::isxdigit(static_cast<unsigned char>(text[i + 1])) &&
               std::isxdigit(static_cast<unsigned char>(text[i + 2]))) {
      out += static_cast<char>(std::stoi(text.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

std::optional<std::string> queryParam(const std::string& query, const std::string& name) {
  std::size_t at = 0;
  while (at <= query.size()) {
    const auto end = std::min(query.find('&', at), query.size());
    const std::string pair = query.substr(at, end - at);
    const auto eq = pair.find('=');
    if (pair.substr(0, eq) == name) return eq == std::string::npos ? std::string() : urlDecode(pair.substr(eq + 1));
    at = end + 1;
  }
  return std::nullopt;
}

Response answer(const HttpRequest& request, http::status status, std::string body, const std::string& type) {
  Response res(status, request.message.version());
  res.set(http::field::content_type, type);
  res.body() = std::move(body);
  return res;
}

Response jsonAnswer(const HttpRequest& request, int status, const json& body) {
  return answer(request, static_cast<http::status>(status), body.dump(), "application/json");
}

/// At most `limit` characters of a client's text for a message: printable ASCII, others as '?'.
/// Now as a wall time [s since the epoch], as the run index stamps rejections.
double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string printableExcerpt(const std::string& text, std::size_t limit) {
  std::string out;
  for (const char c : text.substr(0, limit)) out += c >= 0x20 && c < 0x7f ? c : '?';
  return text.size() > limit ? out + "..." : out;
}

Response errorAnswer(const HttpRequest& request, int status, const std::string& error, const std::string& field = {}) {
  json body = {{"error", error}};
  if (!field.empty()) body["field"] = field;
  return jsonAnswer(request, status, body);
}

Response redirect(const HttpRequest& request, const std::string& to) {
  Response res(http::status::see_other, request.message.version());
  res.set(http::field::location, to);
  return res;
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

/// The keys POST /api/runs takes; any other is refused by name (it used to be dropped, and
/// a ring ran on a plain line).
const std::set<std::string>& knownSceneKeys() {
  static const std::set<std::string> keys = {
      "student", "code", "run_id", "mode", "preset", "masses", "positions", "velocities", "restitution",
      "restitution_model", "tc", "elastic_below", "viscoelastic_speed", "ring", "max_collisions",
      "max_run_seconds", "max_bag_bytes"};
  return keys;
}

/// The keys that describe a scene: a preset brings its own.
const std::set<std::string>& sceneKeys() {
  static const std::set<std::string> keys = {"masses", "positions", "velocities", "restitution", "restitution_model",
                                             "tc", "elastic_below", "viscoelastic_speed", "ring"};
  return keys;
}

/// The restitution model and its parameters of body (the CLI's names), into input.
void parseRestitutionModel(const json& body, collision_lab::InitialConditions& input) {
  if (body.contains("restitution_model")) {
    const json& name = body["restitution_model"];
    namespace core = collision_lab::core;
    bool known = false;
    for (const auto kind : {core::RestitutionModelKind::kConstant, core::RestitutionModelKind::kTc,
                            core::RestitutionModelKind::kViscoelastic, core::RestitutionModelKind::kThreshold}) {
      if (name.is_string() && name.get<std::string>() == core::restitutionModelName(kind)) {
        input.restitution_model = static_cast<std::uint8_t>(kind);  // the message's value is the core's
        known = true;
      }
    }
    if (!known) {
      throw FieldError{"restitution_model", "restitution_model must be \"constant\", \"tc\", \"viscoelastic\" or \"threshold\""};
    }
  }
  const auto number = [&body](const char* key, double& into) {
    if (body.contains(key)) into = parseNumber(body[key], key);
  };
  number("tc", input.tc);  // [s]
  number("elastic_below", input.elastic_below);  // [m/s]
  number("viscoelastic_speed", input.viscoelastic_speed);  // [m/s]
  number("ring", input.ring);  // [m]
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
  if (blocking_) blocking_->pool.join();
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

long WebServer::admit(const std::string& key, std::size_t limit) {
  using Clock = std::chrono::steady_clock;
  const auto now = Clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  auto& sent = sends_[key];
  while (!sent.empty() && now - sent.front() >= std::chrono::minutes(1)) sent.pop_front();
  if (sent.size() >= limit) {
    const auto wait = std::chrono::minutes(1) - (now - sent.front());
    return std::max<long>(1, std::chrono::ceil<std::chrono::seconds>(wait).count());
  }
  sent.push_back(now);
  // Bounded: keys idle for a minute are dropped once the map grows.
  if (sends_.size() > 4096) {
    for (auto it = sends_.begin(); it != sends_.end();) {
      it = (it->second.empty() || now - it->second.back() >= std::chrono::minutes(1)) ? sends_.erase(it) : std::next(it);
    }
  }
  return 0;
}

long WebServer::lockedOut(const std::string& client) {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = locked_until_.find(client);
  if (it == locked_until_.end()) return 0;
  if (now >= it->second) {
    locked_until_.erase(it);
    return 0;
  }
  return std::max<long>(1, std::chrono::ceil<std::chrono::seconds>(it->second - now).count());
}

long WebServer::wrongCode(const std::string& client) {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  auto& wrong = wrong_codes_[client];
  while (!wrong.empty() && now - wrong.front() >= std::chrono::minutes(1)) wrong.pop_front();
  wrong.push_back(now);
  while (!wrong_codes_total_.empty() && now - wrong_codes_total_.front() >= std::chrono::minutes(1)) {
    wrong_codes_total_.pop_front();
  }
  const bool budget_spent = wrong_codes_total_.size() >= config_.code_attempts_total;
  if (!budget_spent) wrong_codes_total_.push_back(now);  // bounded by the budget
  if (wrong.size() < config_.code_attempts && !budget_spent) return 0;
  wrong.clear();
  wrong_codes_.erase(client);
  const auto lockout = std::chrono::milliseconds(static_cast<long long>(config_.code_lockout * 1000));
  locked_until_[client] = now + lockout;
  if (wrong_codes_.size() > 4096) wrong_codes_.clear();  // bounded; the lockouts stay
  return std::max<long>(1, std::chrono::ceil<std::chrono::seconds>(lockout).count());
}

bool WebServer::hostAllowed(const std::string& host) const { return hosts_.count(hostName(host)) > 0; }

bool WebServer::originAllowed(const std::string& origin, const std::string& host) const {
  const auto scheme = origin.find("://");
  if (scheme == std::string::npos) return false;
  const std::string authority = origin.substr(scheme + 3);
  if (!hostAllowed(authority)) return false;
  // Same port as the page's: another service on the lab machine is another site.
  const auto port_of = [](const std::string& text) {
    const auto close = text.rfind(']');
    const auto colon = text.rfind(':');
    if (colon == std::string::npos || (close != std::string::npos && colon < close)) return std::string("80");
    return text.substr(colon + 1);
  };
  return port_of(authority) == (host.empty() ? std::to_string(port_) : port_of(host));
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
        log("wrong code from " + request.client);
        if (const long wait = wrongCode(request.client)) {
          Response res = errorAnswer(request, 429, "too many wrong codes from your address; try again in " + std::to_string(wait) + " s", "code");
          res.set(http::field::retry_after, std::to_string(wait));
          return reply.send(std::move(res));
        }
        return reply.send(errorAnswer(request, 403, "wrong code", "code"));
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

void WebServer::route(const HttpRequest& request, const Access& access, const HttpReply& reply) {
  const auto& m = request.message;
  const std::string target(m.target());
  const auto question = target.find('?');
  const std::string path = target.substr(0, question);
  const std::string query = question == std::string::npos ? std::string() : target.substr(question + 1);
  const bool get = m.method() == http::verb::get;
  const bool post = m.method() == http::verb::post;
  if (!get && !post) {
    Response res = errorAnswer(request, 405, "only GET and POST are served");
    res.set(http::field::allow, "GET, POST");
    return reply.send(std::move(res));
  }
  std::smatch match;
  auto page = [&](const std::string& name) {
    reply.send(answer(request, http::status::ok, files_.at("/static/" + name), contentType(name)));
  };

  if (get && path == "/") return page("index.html");
  if (get && path == "/login") return page("login.html");
  if (get && path == "/teacher") {
    if (!access.teacher) return reply.send(redirect(request, "/login?teacher=1"));
    return page("teacher.html");
  }
  if (get && path.rfind("/static/", 0) == 0) {
    auto it = files_.find(path);
    if (it == files_.end()) return reply.send(errorAnswer(request, 404, "no such file"));
    Response res = answer(request, http::status::ok, it->second, contentType(path));
    res.set(http::field::cache_control, "max-age=3600");
    return reply.send(std::move(res));
  }
  // The run page: the run_id goes into the page escaped, in one attribute the scripts read.
  static const std::regex run_page("/runs/" + kRunId);
  if (get && std::regex_match(path, match, run_page)) {
    const std::string run_id = match[1];
    if (!book_.has(run_id)) return reply.send(errorAnswer(request, 404, "no such run"));
    std::string html = files_.at("/static/run.html");
    const std::string slot = "{{RUN_ID}}";
    const std::string escaped = htmlEscape(run_id);
    for (auto at = html.find(slot); at != std::string::npos; at = html.find(slot, at)) {
      html.replace(at, slot.size(), escaped);
      at += escaped.size();
    }
    return reply.send(answer(request, http::status::ok, std::move(html), "text/html; charset=utf-8"));
  }
  if (post && path == "/api/login") return login(request, reply);
  if (get && path == "/api/presets") {
    json out = json::array();
    try {
      for (const auto& entry : collision_lab::io::loadScenes(config_.scenario_file)) {
        const auto& s = entry.scene;
        json item = {{"name", entry.name}, {"description", entry.description}, {"bodies", s.masses.size()}};
        if (s.masses.size() <= kPresetSceneMaxBodies) {
          json masses = json::array();
          for (double x : s.masses) masses.push_back(std::isinf(x) ? json("inf") : json(x));
          item["scene"] = {{"masses", masses},
                           {"positions", s.positions},
                           {"velocities", s.velocities},
                           {"restitution", s.restitution},
                           {"max_collisions", entry.max_collisions}};
          // The model and ring as POST /api/runs takes them (none for the defaults).
          const auto& model = s.restitution_model;
          if (model.kind != collision_lab::core::RestitutionModelKind::kConstant) {
            item["scene"]["restitution_model"] = collision_lab::core::restitutionModelName(model.kind);
            switch (model.kind) {
              case collision_lab::core::RestitutionModelKind::kTc: item["scene"]["tc"] = model.tc; break;
              case collision_lab::core::RestitutionModelKind::kThreshold:
                item["scene"]["elastic_below"] = model.elastic_below;
                break;
              case collision_lab::core::RestitutionModelKind::kViscoelastic:
                item["scene"]["viscoelastic_speed"] = model.viscoelastic_speed;
                break;
              default: break;
            }
          }
          if (s.isRing()) item["scene"]["ring"] = s.ring;
        }
        out.push_back(item);
      }
    } catch (const std::exception& e) {
      return reply.send(errorAnswer(request, 500, e.what()));
    }
    return reply.send(jsonAnswer(request, 200, out));
  }
  if (get && path == "/api/body_colours") {
    // rviz's palette, body i in palette[i % size] (RunView's colours), for the start page's form.
    json palette = json::array();
    for (std::size_t i = 0; i < collision_lab_ros::markers::layout::kPaletteSize; ++i) {
      palette.push_back(collision_lab_ros::bodyColourHex(i));
    }
    return reply.send(jsonAnswer(request, 200, json{{"palette", palette}}));
  }
  if (post && path == "/api/runs") return postRun(request, reply);
  if (get && path == "/api/runs") {
    std::optional<std::string> student = queryParam(query, "student");
    return boost::asio::post(blocking_->readers, [this, request, reply, student] {
      reply.send(answer(request, http::status::ok, book_.list(student), "application/json"));
    });
  }
  if (get && path == "/api/rejections") {
    if (!access.teacher) return reply.send(errorAnswer(request, 403, "only the teacher sees the rejected inputs", "code"));
    std::optional<std::string> student = queryParam(query, "student");
    return reply.send(answer(request, http::status::ok, rejectionsJson(student), "application/json"));
  }
  if (get && path == "/api/queue") {
    std::string body;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      body = queue_json_;
    }
    if (body.empty()) body = json{{"workers", 0}, {"short_lane_workers", 0}, {"stamp", 0.0}, {"runs", json::array()}}.dump();
    return reply.send(answer(request, http::status::ok, std::move(body), "application/json"));
  }
  static const std::regex student_stop("/api/students/([A-Za-z0-9_-]{1,64})/stop");
  if (post && std::regex_match(path, match, student_stop)) return stopStudent(request, match[1], access, reply);
  static const std::regex run_api("/api/runs/" + kRunId + "(/events\\.csv|/table\\.csv|/worldlines|/bag|/stream|/stop)?");
  if (std::regex_match(path, match, run_api)) {
    const std::string run_id = match[1], what = match[2];
    if (post && what == "/stop") return stopRun(request, run_id, access, reply);
    if (get && what.empty()) {
      const auto send = [this, request, reply, run_id] {
        const auto run = book_.json(run_id);
        if (!run) return reply.send(errorAnswer(request, 404, "no such run"));
        reply.send(answer(request, http::status::ok, run->first, "application/json"));
      };
      if (book_.resident(run_id)) return send();
      return boost::asio::post(blocking_->readers, send);  // read back from its bag
    }
    if (get && what == "/events.csv") return sendEventsCsv(request, run_id, reply);
    if (get && what == "/table.csv") return sendClassTable(request, run_id, reply);
    if (get && what == "/worldlines") return sendWindow(request, run_id, query, reply);
    if (get && what == "/bag") return sendBag(request, run_id, reply);
    if (get && what == "/stream") return stream(request, run_id, reply);
  }
  reply.send(errorAnswer(request, 404, "not found"));
}

void WebServer::login(const HttpRequest& request, const HttpReply& reply) {
  const json body = json::parse(request.message.body(), nullptr, false);
  if (!body.is_object() || !body.contains("code") || !body["code"].is_string() ||
      body["code"].get<std::string>().size() > 256) {
    return reply.send(errorAnswer(request, 400, "send {\"code\": \"...\"}", "code"));
  }
  if (const long wait = lockedOut(request.client)) {
    Response res = errorAnswer(request, 429, "too many wrong codes from your address; try again in " + std::to_string(wait) + " s", "code");
    res.set(http::field::retry_after, std::to_string(wait));
    return reply.send(std::move(res));
  }
  const std::string code = body["code"];
  const bool teacher = !config_.teacher_code.empty() && sameSecret(code, config_.teacher_code);
  const bool student = teacher || (!config_.code.empty() && sameSecret(code, config_.code));
  if (!student) {
    log("wrong code at login from " + request.client);
    if (const long wait = wrongCode(request.client)) {
      Response res = errorAnswer(request, 429, "too many wrong codes from your address; try again in " + std::to_string(wait) + " s", "code");
      res.set(http::field::retry_after, std::to_string(wait));
      return reply.send(std::move(res));
    }
    return reply.send(errorAnswer(request, 403, "wrong code", "code"));
  }
  Response res = jsonAnswer(request, 200, {{"role", teacher ? "teacher" : "student"}});
  const std::string attributes = "; Path=/; Max-Age=" + std::to_string(kCookieSeconds) + "; HttpOnly; SameSite=Strict";
  res.insert(http::field::set_cookie, std::string(kClassCookie) + "=" + secrets_.classCookie() + attributes);
  if (teacher) res.insert(http::field::set_cookie, std::string(kTeacherCookie) + "=" + secrets_.teacherCookie() + attributes);
  reply.send(std::move(res));
}

void WebServer::postRun(const HttpRequest& request, const HttpReply& reply) {
  const std::string& text = request.message.body();
  // Each refusal here is listed on the teacher page too (refusedSend).
  const auto refuse = [&](int status, const std::string& error, const std::string& field = {}) {
    refusedSend(text, "HTTP " + std::to_string(status), error, field);
    return errorAnswer(request, status, error, field);
  };
  json body = json::parse(text, nullptr, false);
  if (body.is_discarded()) return reply.send(refuse(400, "the body is not JSON"));
  if (!body.is_object()) return reply.send(refuse(400, "the body must be a JSON object"));
  if (!body.contains("student") || !body["student"].is_string() || body["student"].get<std::string>().empty()) {
    return reply.send(refuse(400, "student is required: your name", "student"));
  }
  const std::string student = body["student"];
  if (student.size() > collision_lab_ros::kMaxStudentLength) {
    log("refused a scene from " + request.client + ": a name of " + std::to_string(student.size()) + " bytes");
    return reply.send(refuse(400,
                             "student is longer than " + std::to_string(collision_lab_ros::kMaxStudentLength) +
                                 " characters",
                             "student"));
  }
  collision_lab::InitialConditions input;
  try {
    for (const auto& item : body.items()) {
      if (!knownSceneKeys().count(item.key())) {
        throw FieldError{printableExcerpt(item.key(), 40), "unknown key \"" + printableExcerpt(item.key(), 40) +
                                         "\": a send has student (and code), a scene as masses, positions, "
                                         "velocities, restitution, restitution_model, tc, elastic_below, "
                                         "viscoelastic_speed and ring, or as a preset; and max_collisions, "
                                         "max_run_seconds, max_bag_bytes, mode, run_id"};
      }
      if (body.contains("preset") && sceneKeys().count(item.key())) {
        throw FieldError{item.key(), item.key() + " cannot change a preset: send the whole scene instead"};
      }
    }
    if (body.contains("preset")) {
      if (!body["preset"].is_string()) throw FieldError{"preset", "preset must be a preset's name"};
      collision_lab::io::SceneEntry entry;
      try {
        entry = collision_lab::io::findScene(collision_lab::io::loadScenes(config_.scenario_file), body["preset"]);
      } catch (const collision_lab::io::ScenarioFileError& e) {
        throw FieldError{"preset", e.what()};
      }
      input = collision_lab_ros::toInitialConditions(entry.scene, collision_lab::core::RunMode::kFull, entry.max_collisions);
    } else {
      input.masses = parseList(body, "masses", true);
      input.positions = parseList(body, "positions", true);
      input.velocities = parseList(body, "velocities", true);
      input.restitution = parseList(body, "restitution", false);
      parseRestitutionModel(body, input);
    }
    if (body.contains("max_collisions")) {
      const json& cap = body["max_collisions"];
      if (!cap.is_number_unsigned()) throw FieldError{"max_collisions", "max_collisions must be a whole number >= 0"};
      input.max_collisions = cap.get<std::uint64_t>();
    }
    if (body.contains("max_run_seconds")) {
      const json& limit = body["max_run_seconds"];
      if (!limit.is_number() || !(limit.get<double>() >= 0)) {
        throw FieldError{"max_run_seconds", "max_run_seconds must be a number of seconds >= 0"};
      }
      input.max_run_seconds = limit.get<double>();
    }
    if (body.contains("max_bag_bytes")) {
      const json& limit = body["max_bag_bytes"];
      if (!limit.is_number_unsigned()) throw FieldError{"max_bag_bytes", "max_bag_bytes must be a whole number >= 0"};
      input.max_bag_bytes = limit.get<std::uint64_t>();
    }
    if (body.contains("mode")) {
      const json& mode = body["mode"];
      if (!mode.is_number_unsigned() || mode.get<std::uint64_t>() > 255) throw FieldError{"mode", "mode must be 0, 1 or 2"};
      input.mode = static_cast<std::uint8_t>(mode.get<std::uint64_t>());
    }
    if (body.contains("run_id")) {
      if (!body["run_id"].is_string() || body["run_id"].get<std::string>().size() > kMaxRunIdLength) {
        throw FieldError{"run_id", "run_id must be text of at most " + std::to_string(kMaxRunIdLength) + " characters"};
      }
      input.run_id = body["run_id"];
    }
  } catch (const FieldError& e) {
    log("refused a scene from " + request.client + " (" + student + "): " + e.field);
    return reply.send(refuse(400, e.message, e.field));
  }
  if (input.masses.size() > config_.max_bodies) {
    collision_lab::Rejected r;
    r.reason = collision_lab::Rejected::TOO_MANY_BODIES;
    r.reason_name = "TOO_MANY_BODIES";
    r.field = "masses";
    r.message = std::to_string(input.masses.size()) + " bodies are more than this lab's max_bodies = " +
                std::to_string(config_.max_bodies);
    refusedSend(text, r.reason_name, r.message, r.field);
    return reply.send(jsonAnswer(request, 422, rejectionJson(r)));
  }
  // One address holds a bounded share of the lab, whatever names it types.
  if (!shares_.reserve(request.client, [this](const std::string& run_id) { return book_.finished(run_id); })) {
    log("limited " + request.client + " (" + student + "): unfinished runs per address");
    Response res = refuse(429, "at most " + std::to_string(shares_.perAddress()) +
                                   " runs from one address may be queued or running at once; try again when one "
                                   "has finished (or stop one)");
    res.set(http::field::retry_after, std::to_string(kUnfinishedRetryAfter));
    return reply.send(std::move(res));
  }
  // Per address and per name: another name does not escape the limit, and sending as a
  // classmate from elsewhere only spends the classmate's runs as well as one's own.
  long wait = admit("address " + request.client, config_.runs_per_minute_per_address);
  std::string which = "runs per address";
  std::size_t limit = config_.runs_per_minute_per_address;
  if (!wait) {
    wait = admit("student " + student, config_.runs_per_minute);
    which = "runs per student";
    limit = config_.runs_per_minute;
  }
  if (wait) {
    shares_.answered(request.client, std::nullopt);
    log("limited " + request.client + " (" + student + "): " + which);
    Response res = refuse(429, "at most " + std::to_string(limit) + " " + which + " per minute; try again in " +
                                   std::to_string(wait) + " s");
    res.set(http::field::retry_after, std::to_string(wait));
    return reply.send(std::move(res));
  }
  const std::string client = request.client;
  // Each input gets a run_id of its own to ask for, so that its answer is found: the
  // student's next run number.
  const bool numbered = input.run_id.empty();
  if (numbered) {
    std::lock_guard<std::mutex> lock(mutex_);
    input.run_id = "run" + std::to_string(++runs_numbered_[student]);
  }
  input.student = student;
  const std::string requested = input.run_id;
  // A send that makes no run (rejected, or unanswered: 503) gives its number back to the
  // student's next send, unless a later send of theirs took a higher one meanwhile. Should
  // the lab node run an unanswered one after all, it serves the next send as the next free
  // number: nothing is overwritten.
  const auto give_back_number = [this, student, requested, client] {
    shares_.answered(client, std::nullopt);
    if (const auto number = runNumber(student + "." + requested, student)) {
      std::lock_guard<std::mutex> lock(mutex_);
      std::uint64_t& highest = runs_numbered_[student];
      if (highest == *number) --highest;
    }
  };
  const std::string token = WebSecrets::randomToken();
  auto timer = std::make_shared<boost::asio::steady_timer>(
      reply.executor(), std::chrono::milliseconds(static_cast<long long>(config_.answer_timeout * 1000)));
  bool already_sent = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    already_sent = !pending_.emplace(student, requested).second;
  }
  if (already_sent) {  // the same send twice at once (a double click): one answer each
    shares_.answered(client, std::nullopt);
    return reply.send(refuse(409, "run_id '" + requested + "' of " + student +
                                      " is being sent already; wait for its answer", "run_id"));
  }
  book_.expect(student, requested, [this, request, reply, timer, token, student, requested, numbered, client,
                                    give_back_number](const Submission& answer) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      pending_.erase({student, requested});
    }
    boost::asio::post(reply.executor(), [timer] { timer->cancel(); });
    if (answer.rejected) {
      give_back_number();
      if (numbered) {
        std::lock_guard<std::mutex> lock(mutex_);
        numbered_rejections_.push_back({wallSeconds(), student, requested, {}, {}, {}});
        if (numbered_rejections_.size() > kRefusalsKept) numbered_rejections_.pop_front();
      }
      return reply.send(jsonAnswer(request, 422, rejectionJson(*answer.rejected)));
    }
    if (const auto number = runNumber(*answer.run_id, student)) {
      std::lock_guard<std::mutex> lock(mutex_);
      std::uint64_t& highest = runs_numbered_[student];
      highest = std::max(highest, *number);
    }
    secrets_.rememberStopToken(*answer.run_id, token);
    shares_.answered(client, *answer.run_id);
    reply.send(jsonAnswer(request, 202,
                          {{"run_id", *answer.run_id},
                           {"url", "/runs/" + *answer.run_id},
                           {"queue_position", answer.queue_position},
                           {"lane", answer.lane},
                           {"stop_token", token}}));
  });
  if (!publish_(input)) {
    if (book_.forget(student, requested)) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        pending_.erase({student, requested});
      }
      give_back_number();
      reply.send(errorAnswer(request, 503, "the lab node is not listening; ask the teacher"));
    }
    return;
  }
  timer->async_wait([this, request, reply, timer, student, requested, give_back_number](boost::system::error_code ec) {
    if (ec || !book_.forget(student, requested)) return;  // answered meanwhile
    {
      std::lock_guard<std::mutex> lock(mutex_);
      pending_.erase({student, requested});
    }
    give_back_number();
    reply.send(errorAnswer(request, 503, "the lab node did not answer; ask the teacher"));
  });
}

void WebServer::refusedSend(const std::string& body, const std::string& reason_name, const std::string& error,
                            const std::string& field) {
  Refusal refusal{wallSeconds(), {}, {}, reason_name, field, error};
  const json parsed = json::parse(body, nullptr, false);
  const auto text = [&](const char* key) {
    return parsed.is_object() && parsed.contains(key) && parsed[key].is_string()
               ? printableExcerpt(parsed[key].get<std::string>(), 200)
               : std::string();
  };
  refusal.student = text("student");
  refusal.run_id = text("run_id");
  std::lock_guard<std::mutex> lock(mutex_);
  refusals_.push_back(std::move(refusal));
  if (refusals_.size() > kRefusalsKept) refusals_.pop_front();
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

void WebServer::stopRun(const HttpRequest& request, const std::string& run_id, const Access& access,
                        const HttpReply& reply) {
  if (!secrets_.hasStopToken(run_id) && !book_.has(run_id)) return reply.send(errorAnswer(request, 404, "no such run"));
  std::string token(request.message["X-Stop-Token"]);
  if (token.empty() && !request.message.body().empty()) {
    const json body = json::parse(request.message.body(), nullptr, false);
    if (body.is_object() && body.contains("stop_token") && body["stop_token"].is_string()) token = body["stop_token"];
  }
  std::string requested_by;
  if (!token.empty() && secrets_.stopTokenMatches(run_id, token)) {
    requested_by = "its student";
  } else if (access.teacher && !config_.teacher_code.empty()) {
    requested_by = "the teacher";
  } else {
    log("refused a stop of " + run_id + " from " + request.client);
    return reply.send(errorAnswer(request, 403, "only the run's student (its stop_token) or the teacher may stop it"));
  }
  if (!cancel_) return reply.send(errorAnswer(request, 503, "this server cannot reach the lab node's cancel service"));
  boost::asio::post(blocking_->pool, [this, request, reply, run_id, requested_by] {
    std::optional<CancelAnswer> answer;
    try {
      answer = cancel_(run_id, requested_by);
    } catch (const std::exception&) {
    }
    if (!answer) return reply.send(errorAnswer(request, 503, "the lab node's cancel service did not answer"));
    reply.send(jsonAnswer(request, 200, {{"ok", answer->ok}, {"message", answer->message}, {"requested_by", requested_by}}));
  });
}

void WebServer::stopStudent(const HttpRequest& request, const std::string& student, const Access& access,
                            const HttpReply& reply) {
  if (!access.teacher || config_.teacher_code.empty()) {
    return reply.send(errorAnswer(request, 403, "only the teacher may stop all of a student's runs", "code"));
  }
  if (!cancel_) return reply.send(errorAnswer(request, 503, "this server cannot reach the lab node's cancel service"));
  std::vector<std::string> unfinished;
  const json runs = json::parse(book_.list(student), nullptr, false);
  for (const json& run : runs.is_array() ? runs : json::array()) {
    const std::string state = run.value("state", "");
    if (state == "queued" || state == "running") unfinished.push_back(run.value("run_id", ""));
  }
  boost::asio::post(blocking_->pool, [this, request, reply, student, unfinished] {
    json stopped = json::array(), not_stopped = json::array();
    for (const std::string& run_id : unfinished) {
      std::optional<CancelAnswer> answer;
      try {
        answer = cancel_(run_id, "the teacher");
      } catch (const std::exception&) {
      }
      if (answer && answer->ok) {
        stopped.push_back(run_id);
      } else {
        not_stopped.push_back({{"run_id", run_id}, {"message", answer ? answer->message : "the lab node did not answer"}});
      }
    }
    log("the teacher stopped " + std::to_string(stopped.size()) + " runs of " + student);
    reply.send(jsonAnswer(request, 200, {{"student", student}, {"stopped", stopped}, {"not_stopped", not_stopped}}));
  });
}

namespace {

/// The bag and a file of its folder as an attachment, streamed from disk.
std::optional<http::response<http::file_body>> fileAnswer(const HttpRequest& request, const std::string& path,
                                                          const std::string& type, const std::string& name) {
  http::file_body::value_type file;
  boost::beast::error_code ec;
  file.open(path.c_str(), boost::beast::file_mode::scan, ec);
  if (ec) return std::nullopt;
  http::response<http::file_body> res(http::status::ok, request.message.version());
  res.set(http::field::content_type, type);
  res.set(http::field::content_disposition, "attachment; filename=\"" + name + "\"");
  res.body() = std::move(file);
  return res;
}

}  // namespace

void WebServer::sendMadeFromBag(const HttpRequest& request, const std::string& run_id, const std::string& name,
                                MakeFromBag make, const HttpReply& reply) {
  if (!book_.has(run_id)) return reply.send(errorAnswer(request, 404, "no such run"));
  if (!book_.finished(run_id)) return reply.send(errorAnswer(request, 409, "the run is not finished yet"));
  const std::string bag = book_.bagPath(run_id);
  if (bag.empty()) return reply.send(errorAnswer(request, 404, "the run was not recorded"));
  const std::string file_name = run_id + "_" + name;
  const fs::path made = fs::path(bag).parent_path() / file_name;
  if (auto res = fileAnswer(request, made.string(), "text/csv", file_name)) return reply.sendFile(std::move(*res));
  // Made once, beside the bag, off the I/O threads; a file made by another request
  // meanwhile is simply replaced by an identical one.
  boost::asio::post(blocking_->pool, [this, request, reply, bag, made, file_name, make = std::move(make)] {
    std::string folder = (made.parent_path() / ("." + file_name + ".XXXXXX")).string();
    if (!mkdtemp(folder.data())) return reply.send(errorAnswer(request, 500, "cannot write beside the bag"));
    std::string error, why_not;
    try {
      const std::string path = make(bag, folder, why_not);
      if (!path.empty()) fs::rename(path, made);
    } catch (const std::exception& e) {
      error = e.what();
    }
    collision_lab_ros::releaseMemoryAfterBag(bag);
    std::error_code ignored;
    fs::remove_all(folder, ignored);
    if (!error.empty()) return reply.send(errorAnswer(request, 500, error));
    if (!why_not.empty()) return reply.send(errorAnswer(request, 404, why_not));
    auto res = fileAnswer(request, made.string(), "text/csv", file_name);
    if (!res) return reply.send(errorAnswer(request, 500, "the converted CSV is gone"));
    reply.sendFile(std::move(*res));
  });
}

void WebServer::sendEventsCsv(const HttpRequest& request, const std::string& run_id, const HttpReply& reply) {
  sendMadeFromBag(request, run_id, "events.csv", [](const std::string& bag, const std::string& folder, std::string& why) {
    for (const auto& file : collision_lab_ros::bagToCsv(bag, folder).files) {
      if (fs::path(file.path).filename() == "collision_events.csv") return file.path;
    }
    why = "the run has no collision events to export: it was not simulated, or had no impact";
    return std::string();
  }, reply);
}

// The class table: the state at the start and after each event, a column per body.
void WebServer::sendClassTable(const HttpRequest& request, const std::string& run_id, const HttpReply& reply) {
  sendMadeFromBag(request, run_id, "table.csv", [](const std::string& bag, const std::string& folder, std::string& why) {
    const std::string path = folder + "/table.csv";
    const auto table = collision_lab_ros::bagToClassTable(bag, path, kClassTableMaxBodies);
    if (table.too_many_bodies) {
      why = "the class table has a column per body and is made for at most " + std::to_string(kClassTableMaxBodies) +
            " bodies; this run has " + std::to_string(table.bodies) + " (its events CSV has every impact)";
    } else if (table.events_missing) {
      why = "the run was recorded without all its events (it was not simulated, or ran in summary mode), so the table "
            "cannot show it";
    }
    return why.empty() ? path : std::string();
  }, reply);
}

// GET /api/runs/<run_id>/worldlines?from=T0&to=T1&bodies=0,1,2: the x-t diagram of a time
// window, from every event in the bag (windowWorldlines), read on the reader pool.
void WebServer::sendWindow(const HttpRequest& request, const std::string& run_id, const std::string& query,
                           const HttpReply& reply) {
  if (!book_.has(run_id)) return reply.send(errorAnswer(request, 404, "no such run"));
  if (!book_.finished(run_id)) return reply.send(errorAnswer(request, 409, "the run is not finished yet"));
  const std::string bag = book_.bagPath(run_id);
  if (bag.empty()) return reply.send(errorAnswer(request, 404, "the run was not recorded"));
  const auto number = [&](const char* name) {
    const auto text = queryParam(query, name);
    char* end = nullptr;
    const double value = text ? std::strtod(text->c_str(), &end) : std::nan("");
    return text && end && *end == '\0' && std::isfinite(value) ? value : std::nan("");
  };
  const double from = number("from"), to = number("to");
  if (!(from >= 0.0 && from < to)) {
    return reply.send(errorAnswer(request, 400, "give from and to [s] with 0 <= from < to", "from"));
  }
  std::vector<std::size_t> bodies;
  const std::string list = queryParam(query, "bodies").value_or("");
  for (std::size_t at = 0; at < list.size() && bodies.size() < kWindowMaxBodies;) {
    const std::size_t end = std::min(list.find(',', at), list.size());
    const std::string item = list.substr(at, end - at);
    if (item.empty() || item.find_first_not_of("0123456789") != std::string::npos || item.size() > 9) {
      return reply.send(errorAnswer(request, 400, "bodies: body indices separated by commas", "bodies"));
    }
    bodies.push_back(std::stoul(item));
    at = end + 1;
  }
  boost::asio::post(blocking_->readers, [this, request, reply, bag, from, to, bodies] {
    json lines = json::array();
    bool exact = true;
    try {
      const auto window = windowWorldlines(bag, from, to, bodies, kWindowVertices);
      exact = window.exact;
      for (const auto& line : window.lines) {
        json points = json::array();
        for (const auto& [t, x] : line.points) points.push_back({t, x});
        lines.push_back({{"body", line.body}, {"points", std::move(points)}});
      }
    } catch (const std::invalid_argument& e) {
      return reply.send(errorAnswer(request, 400, e.what()));
    } catch (const std::exception& e) {
      return reply.send(errorAnswer(request, 500, e.what()));
    }
    collision_lab_ros::releaseMemoryAfterBag(bag);
    reply.send(jsonAnswer(request, 200, {{"from", from}, {"to", to}, {"exact", exact}, {"lines", std::move(lines)}}));
  });
}

// The bag: only the file its RunSummary names, and only when that file is <run_id>.bag.
void WebServer::sendBag(const HttpRequest& request, const std::string& run_id, const HttpReply& reply) {
  const std::string bag = book_.bagPath(run_id);
  const std::string name = run_id + ".bag";
  if (bag.empty() || bag.size() < name.size() + 1 ||
      bag.compare(bag.size() - name.size() - 1, std::string::npos, "/" + name) != 0) {
    return reply.send(errorAnswer(request, 404, "no recorded bag for this run"));
  }
  auto res = fileAnswer(request, bag, "application/octet-stream", name);
  if (!res) return reply.send(errorAnswer(request, 404, "the bag is gone"));
  reply.sendFile(std::move(*res));
}

// Server-Sent Events: the run as JSON (as GET /api/runs/<run_id>) whenever it changed, at
// most every kStreamInterval; an event `final` ends the stream. A timer per stream, no thread.
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
