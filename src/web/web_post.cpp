// POST /api/runs (a scene sent to the lab node, with every check and limit on the way) and
// the stops: a run by its student or the teacher, all of a student's runs by the teacher.
#include "web_parts.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <set>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>

#include "collision_lab/Rejected.h"
#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/service/envelope.h"

namespace collision_lab_web {

namespace {

/// Longest run_id the lab node takes [characters].
constexpr std::size_t kMaxRunIdLength = 128;
constexpr int kUnfinishedRetryAfter = 5;  ///< [s] Retry-After of a 429 for unfinished runs

/// n of a run served as "<student>.run<n>" (the student's n-th run); nullopt for any other id.
std::optional<std::uint64_t> runNumber(const std::string& run_id, const std::string& student) {
  const std::string prefix = student + ".run";
  if (run_id.size() <= prefix.size() || run_id.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  const std::string digits = run_id.substr(prefix.size());
  if (digits.size() > 18 || digits.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return std::stoull(digits);
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

}  // namespace

/// The answer to a send refused here, which is listed on the teacher page too (refusedSend).
struct WebServer::Refuse {
  WebServer& server;
  const HttpRequest& request;
  Response operator()(int status, const std::string& error, const std::string& field = {}) const {
    server.refusedSend(request.message.body(), "HTTP " + std::to_string(status), error, field);
    return errorAnswer(request, status, error, field);
  }
};

void WebServer::postRun(const HttpRequest& request, const HttpReply& reply) {
  const std::string& text = request.message.body();
  const Refuse refuse{*this, request};
  json body = json::parse(text, nullptr, false);
  if (body.is_discarded()) return reply.send(refuse(400, "the body is not JSON"));
  if (!body.is_object()) return reply.send(refuse(400, "the body must be a JSON object"));
  if (!body.contains("student") || !body["student"].is_string() || body["student"].get<std::string>().empty()) {
    return reply.send(refuse(400, "student is required: your name", "student"));
  }
  const std::string student = body["student"];
  if (student.size() > collision_lab::service::kMaxStudentLength) {
    log("refused a scene from " + request.client + ": a name of " + std::to_string(student.size()) + " bytes");
    return reply.send(refuse(400,
                             "student is longer than " + std::to_string(collision_lab::service::kMaxStudentLength) +
                                 " characters",
                             "student"));
  }
  collision_lab::InitialConditions input;
  try {
    input = sceneOfSend(body);
  } catch (const FieldError& e) {
    log("refused a scene from " + request.client + " (" + student + "): " + e.field);
    return reply.send(refuse(400, e.message, e.field));
  }
  if (!admitSend(request, input, student, refuse, reply)) return;
  input.student = student;
  sendToLab(request, reply, std::move(input), refuse);
}

// The scene and the run's options of a send (POST /api/runs's body); throws FieldError.
collision_lab::InitialConditions WebServer::sceneOfSend(const json& body) const {
  collision_lab::InitialConditions input;
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
  return input;
}

// The envelope of a send (service::checkEnvelope, as the lab checks it: 422 with the lab's
// Rejected), then the limits: the address's share of unfinished runs and the runs per
// minute (429). False when refused (answered here).
bool WebServer::admitSend(const HttpRequest& request, const collision_lab::InitialConditions& input,
                          const std::string& student, const Refuse& refuse, const HttpReply& reply) {
  const std::string& text = request.message.body();
  const std::size_t bodies = std::max({input.masses.size(), input.positions.size(), input.velocities.size()});
  if (const auto refusal =
          collision_lab::service::checkEnvelope({student, input.run_id, input.mode, bodies}, config_.max_bodies)) {
    const collision_lab::Rejected r = collision_lab_ros::toRejectedMsg(*refusal);
    refusedSend(text, r.reason_name, r.message, r.field);
    reply.send(jsonAnswer(request, 422, rejectionJson(r)));
    return false;
  }
  // One address holds a bounded share of the lab, whatever names it types.
  if (!shares_.reserve(request.client, [this](const std::string& run_id) { return book_.finished(run_id); })) {
    log("limited " + request.client + " (" + student + "): unfinished runs per address");
    Response res = refuse(429, "at most " + std::to_string(shares_.perAddress()) +
                                   " runs from one address may be queued or running at once; try again when one "
                                   "has finished (or stop one)");
    res.set(http::field::retry_after, std::to_string(kUnfinishedRetryAfter));
    reply.send(std::move(res));
    return false;
  }
  // Per address, and per name at that address: another name does not escape the address's
  // limit, and sending as a classmate from another address spends none of the classmate's
  // own runs. Each window is looked at first and counted only when all three admit the send,
  // so that a student at the hour's ceiling spends none of the address's minute.
  using std::chrono::hours;
  using std::chrono::minutes;
  const std::string address = "address " + request.client, name = "student " + student + " at " + request.client;
  long wait = 0;
  std::string which, per = "minute";
  std::size_t limit = 0;
  if ((wait = admit(address, config_.runs_per_minute_per_address, minutes(1), false))) {
    which = "runs per address", limit = config_.runs_per_minute_per_address;
  } else if ((wait = admit(name, config_.runs_per_minute, minutes(1), false))) {
    which = "runs per student", limit = config_.runs_per_minute;
  } else if ((wait = admit(name, config_.runs_per_hour, hours(1), false))) {
    which = "runs per student", per = "hour: this lesson's ceiling", limit = config_.runs_per_hour;
  } else {
    admit(address, config_.runs_per_minute_per_address);
    admit(name, config_.runs_per_minute);
    admit(name, config_.runs_per_hour, hours(1));
  }
  if (wait) {
    shares_.answered(request.client, std::nullopt);
    log("limited " + request.client + " (" + student + "): " + which + (per == "minute" ? "" : " per hour"));
    Response res = refuse(429, "at most " + std::to_string(limit) + " " + which + " per " + per + "; try again in " +
                                   std::to_string(wait) + " s");
    res.set(http::field::retry_after, std::to_string(wait));
    reply.send(std::move(res));
    return false;
  }
  return true;
}

// The send handed to the lab node under the student's next run number (or the run_id they
// typed): answered 202 with the run's stop token, 422 when the lab node rejects it, 409 for
// the same send twice at once, 503 when the lab node does not answer.
void WebServer::sendToLab(const HttpRequest& request, const HttpReply& reply, collision_lab::InitialConditions input,
                          const Refuse& refuse) {
  const std::string student = input.student;
  const std::string client = request.client;
  // Each input gets a run_id of its own to ask for, so that its answer is found: the
  // student's next run number.
  const bool numbered = input.run_id.empty();
  if (numbered) {
    std::lock_guard<std::mutex> lock(mutex_);
    input.run_id = "run" + std::to_string(++runs_numbered_[student]);
  }
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

}  // namespace collision_lab_web
