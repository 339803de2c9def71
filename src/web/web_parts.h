// What the web server's files share (web_server.cpp and its parts: web_access.cpp,
// web_post.cpp, web_exports.cpp, web_stream.cpp): answers, query and cookie parsing, the
// blocking pools and a request's access. Internal to src/web.
#pragma once

#include <algorithm>
#include <cctype>
#include <chrono>
#include <optional>
#include <string>

#include <boost/asio/thread_pool.hpp>
#include <nlohmann/json.hpp>

#include "collision_lab/web/web_server.h"
#include "http_server.h"

namespace collision_lab_web {

using nlohmann::json;
using Response = http::response<http::string_body>;

inline constexpr char kClassCookie[] = "collision_lab_class";
inline constexpr char kTeacherCookie[] = "collision_lab_teacher";
/// [s] a login lasts: a school day.
inline constexpr int kCookieSeconds = 12 * 3600;

/// Work kept off the I/O threads: `pool` for cancel calls, `readers` for the run list (the
/// index) and runs read back from their bags, `exports` for files made from bags (CSVs, x-t
/// windows), so that a long conversion holds up neither a Stop nor the run list. Each
/// bounds how many run at once; the I/O threads serve pages and sends meanwhile.
struct BlockingPool {
  boost::asio::thread_pool pool{2};
  boost::asio::thread_pool readers{2};
  boost::asio::thread_pool exports{1};
};

struct WebServer::Access {
  bool student = false;  ///< the class code was given (or none is needed)
  bool teacher = false;  ///< the teacher code was given (or none is needed)
};

/// A run_id in a URL: the node's own alphabet (InitialConditions.run_id). Anything else,
/// '/' and "%2F" included, is no run and gets a 404.
inline const std::string kRunId = "([A-Za-z0-9_.\\-]+)";

inline std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

/// "name:port", "[v6]:port" or "name" -> the name, lower case, without brackets.
inline std::string hostName(const std::string& host) {
  if (!host.empty() && host.front() == '[') return lower(host.substr(1, host.find(']') - 1));
  const auto colon = host.find(':');
  if (colon != std::string::npos && host.find(':', colon + 1) == std::string::npos) return lower(host.substr(0, colon));
  return lower(host);
}

inline std::string cookie(const HttpRequest& request, const std::string& name) {
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

inline std::string urlDecode(const std::string& text) {
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

inline std::optional<std::string> queryParam(const std::string& query, const std::string& name) {
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

inline Response answer(const HttpRequest& request, http::status status, std::string body, const std::string& type) {
  Response res(status, request.message.version());
  res.set(http::field::content_type, type);
  res.body() = std::move(body);
  return res;
}

inline Response jsonAnswer(const HttpRequest& request, int status, const json& body) {
  return answer(request, static_cast<http::status>(status), body.dump(), "application/json");
}

/// Now as a wall time [s since the epoch], as the run index stamps rejections.
inline double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

/// At most `limit` characters of a client's text for a message: printable ASCII, others as '?'.
inline std::string printableExcerpt(const std::string& text, std::size_t limit) {
  std::string out;
  for (const char c : text.substr(0, limit)) out += c >= 0x20 && c < 0x7f ? c : '?';
  return text.size() > limit ? out + "..." : out;
}

inline Response errorAnswer(const HttpRequest& request, int status, const std::string& error, const std::string& field = {}) {
  json body = {{"error", error}};
  if (!field.empty()) body["field"] = field;
  return jsonAnswer(request, status, body);
}

inline Response redirect(const HttpRequest& request, const std::string& to) {
  Response res(http::status::see_other, request.message.version());
  res.set(http::field::location, to);
  return res;
}

}  // namespace collision_lab_web
