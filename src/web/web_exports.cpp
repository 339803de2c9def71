// The downloads made from a finished run's bag: the events CSV, the class table, a time
// window of the x-t diagram, and the bag itself.
#include "web_parts.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include <boost/asio/post.hpp>
#include <boost/beast/http/file_body.hpp>

#include "collision_lab/ros/bag_csv.h"
#include "collision_lab/ros/bag_reading.h"
#include "collision_lab/web/window_worldlines.h"

namespace fs = std::filesystem;

namespace collision_lab_web {

namespace {

/// The class table's widest run: two columns per body, a row per event.
constexpr std::size_t kClassTableMaxBodies = 64;
/// A time window's x-t diagram: at most this many bodies, and vertices per body.
constexpr std::size_t kWindowMaxBodies = 64;
constexpr std::size_t kWindowVertices = 2048;

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

bool WebServer::startExport(const HttpRequest& request, const HttpReply& reply) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (exporting_.insert(request.client).second) return true;
  }
  Response res = errorAnswer(request, 429, "one file made from a bag at a time from your address: wait for the last one");
  res.set(http::field::retry_after, "2");
  reply.send(std::move(res));
  return false;
}

void WebServer::endExport(const std::string& client) {
  std::lock_guard<std::mutex> lock(mutex_);
  exporting_.erase(client);
}

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
  if (!startExport(request, reply)) return;
  boost::asio::post(blocking_->exports, [this, request, reply, bag, made, file_name, make = std::move(make)] {
    // The address may make its next file once this answer is on its way.
    std::shared_ptr<void> done(nullptr, [this, client = request.client](void*) { endExport(client); });
    std::string folder = (made.parent_path() / ("." + file_name + ".XXXXXX")).string();
    if (!mkdtemp(folder.data())) return done.reset(), reply.send(errorAnswer(request, 500, "cannot write beside the bag"));
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
    if (!error.empty()) return done.reset(), reply.send(errorAnswer(request, 500, error));
    if (!why_not.empty()) return done.reset(), reply.send(errorAnswer(request, 404, why_not));
    auto res = fileAnswer(request, made.string(), "text/csv", file_name);
    if (!res) return done.reset(), reply.send(errorAnswer(request, 500, "the converted CSV is gone"));
    done.reset();
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
  if (bodies.empty()) return reply.send(errorAnswer(request, 400, "bodies: which bodies to draw, e.g. 0,1,2", "bodies"));
  if (!startExport(request, reply)) return;
  boost::asio::post(blocking_->exports, [this, request, reply, bag, from, to, bodies] {
    // The address may make its next file once this answer is on its way.
    std::shared_ptr<void> done(nullptr, [this, client = request.client](void*) { endExport(client); });
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
      return done.reset(), reply.send(errorAnswer(request, 400, e.what()));
    } catch (const std::exception& e) {
      return done.reset(), reply.send(errorAnswer(request, 500, e.what()));
    }
    collision_lab_ros::releaseMemoryAfterBag(bag);
    done.reset();
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

}  // namespace collision_lab_web
