// Who may do what: the class and teacher codes (POST /api/login and its cookies), wrong
// codes counted per address and in total, runs per minute, and the Host and Origin checks.
#include "web_parts.h"

#include <algorithm>

#include "collision_lab/ros/node_constants.h"

namespace collision_lab_web {

long WebServer::admit(const std::string& key, std::size_t limit, std::chrono::seconds window, bool count) {
  using Clock = std::chrono::steady_clock;
  const auto now = Clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  auto& sends = window > std::chrono::minutes(1) ? hourly_sends_ : sends_;
  auto& sent = sends[key];
  while (!sent.empty() && now - sent.front() >= window) sent.pop_front();
  if (sent.size() >= limit) {
    const auto wait = window - (now - sent.front());
    return std::max<long>(1, std::chrono::ceil<std::chrono::seconds>(wait).count());
  }
  if (!count) return 0;
  sent.push_back(now);
  // Bounded: keys idle for a whole window are dropped once the map grows.
  if (sends.size() > 4096) {
    for (auto it = sends.begin(); it != sends.end();) {
      it = (it->second.empty() || now - it->second.back() >= window) ? sends.erase(it) : std::next(it);
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

void WebServer::refuseWrongCode(const HttpRequest& request, const std::string& where, const HttpReply& reply) {
  log("wrong code " + where + "from " + request.client);
  if (const long wait = wrongCode(request.client)) {
    Response res = errorAnswer(request, 429, "too many wrong codes from your address; try again in " + std::to_string(wait) + " s", "code");
    res.set(http::field::retry_after, std::to_string(wait));
    return reply.send(std::move(res));
  }
  reply.send(errorAnswer(request, 403, "wrong code", "code"));
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
  if (!student) return refuseWrongCode(request, "at login ", reply);
  Response res = jsonAnswer(request, 200, {{"role", teacher ? "teacher" : "student"}});
  const std::string attributes = "; Path=/; Max-Age=" + std::to_string(kCookieSeconds) + "; HttpOnly; SameSite=Strict";
  res.insert(http::field::set_cookie, std::string(kClassCookie) + "=" + secrets_.classCookie() + attributes);
  if (teacher) res.insert(http::field::set_cookie, std::string(kTeacherCookie) + "=" + secrets_.teacherCookie() + attributes);
  reply.send(std::move(res));
}

}  // namespace collision_lab_web
