#include "collision_lab/web/run_book.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/ros/bag_csv.h"
#include "collision_lab/ros/bag_reading.h"

namespace collision_lab_web {

using collision_lab_ros::Envelope;
using collision_lab_ros::RecordLimits;
using collision_lab_ros::RunRecord;
using nlohmann::json;

namespace {

/// Events that arrive before their run's served_inputs wait here, at most this many per run
/// (the node publishes the input first; the topics are separate connections).
constexpr std::size_t kEarlyEventsKept = 100'000;

std::string key(const std::string& student, const std::string& requested) { return student + '\n' + requested; }

/// Six significant digits: what a plot can show, and a third of the text.
json number(double x) {
  if (!std::isfinite(x)) return nullptr;
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return std::strtod(text, nullptr);
}

/// Exact numbers for tables (JSON has no inf or NaN: null).
json exactNumber(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json numbers(const std::vector<double>& values) {
  json out = json::array();
  for (double v : values) out.push_back(exactNumber(v));
  return out;
}

/// Masses keep "inf" (a wall) readable.
json masses(const std::vector<double>& values) {
  json out = json::array();
  for (double m : values) out.push_back(std::isinf(m) ? json("inf") : exactNumber(m));
  return out;
}

json points(const Envelope& envelope) {
  json out = json::array();
  for (const auto& v : envelope.polyline()) out.push_back(json::array({number(v.x), number(v.y)}));
  return out;
}

json sceneJson(const collision_lab::InitialConditions& in) {
  return {{"masses", masses(in.masses)},
          {"positions", numbers(in.positions)},
          {"velocities", numbers(in.velocities)},
          {"restitution", numbers(in.restitution)},
          {"max_collisions", in.max_collisions},
          {"mode", in.mode}};
}

json predictionJson(const collision_lab::Prediction& p) {
  return {{"model", p.model_name},
          {"model_reason", p.model_reason},
          {"collision_count", p.collision_count_defined ? json(p.collision_count) : json(nullptr)},
          {"infinite_collisions", static_cast<bool>(p.infinite_collisions)},
          {"paper_collision_count", p.paper_collision_count_defined ? json(p.paper_collision_count) : json(nullptr)},
          {"final_velocities", numbers(p.final_velocities)},
          {"energy_lost", exactNumber(p.energy_lost)},
          {"collapsed", static_cast<bool>(p.collapsed)}};
}

json summaryJson(const collision_lab::RunSummary& s) {
  return {{"collision_count", s.collision_count},
          {"model", s.model_name},
          {"model_reason", s.model_reason},
          {"body_count", s.body_count},
          {"simulated", static_cast<bool>(s.simulated)},
          {"truncated", static_cast<bool>(s.truncated)},
          {"truncation_reason", s.truncation_reason},
          {"stop_reason", s.stop_reason},
          {"predicted_collision_count",
           s.predicted_collision_count_defined ? json(s.predicted_collision_count) : json(nullptr)},
          {"paper_collision_count",
           s.paper_predicted_collision_count_defined ? json(s.paper_predicted_collision_count) : json(nullptr)},
          {"infinite_collisions", static_cast<bool>(s.infinite_collisions)},
          {"final_velocities", numbers(s.final_velocities)},
          {"energy_lost", exactNumber(s.energy_lost)},
          {"collapsed", static_cast<bool>(s.collapsed)},
          {"max_prediction_error", exactNumber(s.max_prediction_error)},
          {"energy_relative_drift", exactNumber(s.energy_relative_drift)},
          {"published_events", s.published_events},
          {"compute_time", exactNumber(s.compute_time)},
          {"recorded", s.recording_ok && !s.bag_path.empty()}};
}

/// The plotted series: at most a few thousand points whatever the count.
json plotsJson(const RunRecord& record, const std::vector<Envelope>& predicted) {
  json plots;
  const bool per_body = !record.plottedBodies().empty();
  const auto& bodies = per_body ? record.plottedBodies() : record.trackedBodies();
  json velocity = json::array(), paper = json::array(), closed_form = json::array(), paper_final = json::array();
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const std::size_t i = bodies[k];
    velocity.push_back({{"body", i}, {"points", points(per_body ? record.velocity(i) : record.trackedVelocity(i))}});
    if (per_body && !record.paperVelocity(i).empty()) {
      paper.push_back({{"body", i}, {"points", points(record.paperVelocity(i))}});
      paper_final.push_back(exactNumber(record.paperVelocity(i).last().y));
    }
    if (k < predicted.size() && !predicted[k].empty()) {
      closed_form.push_back({{"body", i}, {"points", points(predicted[k])}});
    }
  }
  json worldlines = json::array();
  for (std::size_t i : record.trackedBodies()) {
    worldlines.push_back({{"body", i}, {"points", points(record.worldline(i))}});
  }
  plots["bodies"] = bodies;
  plots["velocity"] = velocity;
  plots["paper_velocity"] = paper;
  plots["paper_final_velocities"] = paper_final;
  plots["predicted_velocity"] = closed_form;
  plots["energy"] = points(record.energy());
  plots["heat"] = points(record.energyLost());
  plots["worldlines"] = worldlines;
  return plots;
}

void addPredicted(std::vector<Envelope>& predicted, const RunRecord& record, const collision_lab::CollisionEvent& e) {
  if (e.predicted_velocities_after.empty()) return;
  const auto& bodies = record.plottedBodies();
  for (std::size_t k = 0; k < bodies.size() && k < predicted.size(); ++k) {
    const std::size_t i = bodies[k];
    if (i >= e.predicted_velocities_after.size()) continue;
    if (predicted[k].empty()) predicted[k].add(0.0, record.input().velocities[i]);
    predicted[k].step(static_cast<double>(e.index), e.predicted_velocities_after[i]);
  }
}

}  // namespace

RunBook::RunBook(std::size_t envelope_vertices) : envelope_vertices_(envelope_vertices) {}

RunBook::~RunBook() {
  for (auto& t : rebuilds_) t.join();
}

WebRun& RunBook::runLocked(const std::string& run_id) {
  auto [it, inserted] = runs_.try_emplace(run_id);
  if (inserted) {
    it->second.run_id = run_id;
    order_.push_back(run_id);
  }
  return it->second;
}

void RunBook::onAccepted(const collision_lab::AcceptedRun& msg) {
  std::unique_lock<std::mutex> lock(mutex_);
  WebRun& run = runLocked(msg.run_id);
  run.student = msg.student;
  run.requested_run_id = msg.requested_run_id;
  run.accepted_stamp = msg.header.stamp.toSec();
  ++run.version;
  changed_.notify_all();
  AnswerCallback answer = takeWaitingLocked(msg.student, msg.requested_run_id);
  lock.unlock();
  if (answer) answer(Submission{msg.run_id, msg.queue_position, msg.lane, std::nullopt});
}

void RunBook::onRejected(const collision_lab::Rejected& msg) {
  std::unique_lock<std::mutex> lock(mutex_);
  AnswerCallback answer = takeWaitingLocked(msg.student, msg.run_id);
  lock.unlock();
  if (answer) answer(Submission{std::nullopt, 0, {}, msg});
}

RunBook::AnswerCallback RunBook::takeWaitingLocked(const std::string& student, const std::string& requested) {
  auto waiting = waiting_.find(key(student, requested));
  if (waiting == waiting_.end()) return nullptr;
  AnswerCallback answer = std::move(waiting->second);
  waiting_.erase(waiting);
  return answer;
}

void RunBook::onServedInput(const collision_lab::InitialConditions& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  WebRun& run = runLocked(msg.run_id);
  if (run.record) return;
  RecordLimits limits;
  limits.envelope_vertices = envelope_vertices_;
  run.record = std::make_unique<RunRecord>(msg, limits);
  run.predicted.assign(run.record->plottedBodies().size(), Envelope(envelope_vertices_));
  if (run.student.empty()) run.student = msg.student;
  if (run.early_prediction) run.record->prediction = *run.early_prediction;
  for (const auto& e : run.early_events) {
    run.record->add(e);
    addPredicted(run.predicted, *run.record, e);
  }
  run.early_events.clear();
  maybeFinishLocked(run);
  ++run.version;
  changed_.notify_all();
}

void RunBook::onPrediction(const collision_lab::Prediction& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  WebRun& run = runLocked(msg.run_id);
  if (run.record) {
    run.record->prediction = msg;
  } else {
    run.early_prediction = msg;
  }
  ++run.version;
  changed_.notify_all();
}

void RunBook::onEvent(const collision_lab::CollisionEvent& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  WebRun& run = runLocked(msg.run_id);
  if (run.finished || run.rebuilding) return;
  ++run.events_received;
  if (run.record) {
    run.record->add(msg);
    addPredicted(run.predicted, *run.record, msg);
  } else if (run.early_events.size() < kEarlyEventsKept) {
    run.early_events.push_back(msg);
  }
  maybeFinishLocked(run);
  ++run.version;
  changed_.notify_all();
}

void RunBook::onSummary(const collision_lab::RunSummary& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  WebRun& run = runLocked(msg.run_id);
  if (run.finished) return;
  run.pending_summary = msg;
  if (run.student.empty()) run.student = msg.student;
  maybeFinishLocked(run);
  ++run.version;
  changed_.notify_all();
}

void RunBook::maybeFinishLocked(WebRun& run) {
  if (!run.pending_summary || run.rebuilding || run.finished) return;
  const collision_lab::RunSummary& summary = *run.pending_summary;
  if (run.record && run.events_received < summary.published_events) return;  // still on their way
  const bool recorded = summary.recording_ok && !summary.bag_path.empty();
  // No served input yet: the topics are separate connections, so the summary may come
  // first. The bag has the whole run. Without a bag, wait for the served input of a run
  // seen accepted (it was published before the summary); a run joined midway ends with
  // its summary alone.
  if (!run.record && recorded) {
    run.rebuilding = true;
    rebuilds_.emplace_back(&RunBook::rebuildFromBag, this, run.run_id, summary.bag_path);
    return;
  }
  if (!run.record && run.accepted_stamp > 0.0) return;
  if (recorded && run.record && summary.events_not_published) {
    // The bag holds every event; the topics stopped at ~max_published_events.
    run.rebuilding = true;
    rebuilds_.emplace_back(&RunBook::rebuildFromBag, this, run.run_id, summary.bag_path);
    return;
  }
  finishLocked(run, summary);
}

void RunBook::finishLocked(WebRun& run, const collision_lab::RunSummary& summary) {
  if (run.record) run.record->summary = summary;
  run.summary = summary;
  run.pending_summary.reset();
  run.rebuilding = false;
  run.finished = true;
}

void RunBook::rebuildFromBag(const std::string& run_id, const std::string& bag_path) {
  std::optional<BagRun> rebuilt;
  std::string error;
  try {
    rebuilt = readRunFromBag(bag_path, envelope_vertices_);
  } catch (const std::exception& e) {
    error = e.what();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  WebRun& run = runLocked(run_id);
  if (rebuilt && rebuilt->record) {
    run.record = std::move(rebuilt->record);
    run.predicted = std::move(rebuilt->predicted);
  } else {
    run.bag_error = error.empty() ? "the bag has no InitialConditions" : error;
  }
  finishLocked(run, *run.pending_summary);
  ++run.version;
  changed_.notify_all();
}

void RunBook::expect(const std::string& student, const std::string& requested, AnswerCallback on_answer) {
  std::lock_guard<std::mutex> lock(mutex_);
  waiting_[key(student, requested)] = std::move(on_answer);
}

bool RunBook::forget(const std::string& student, const std::string& requested) {
  std::lock_guard<std::mutex> lock(mutex_);
  return waiting_.erase(key(student, requested)) > 0;
}

bool RunBook::has(const std::string& run_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return runs_.count(run_id) > 0;
}

bool RunBook::finished(const std::string& run_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = runs_.find(run_id);
  return it != runs_.end() && it->second.finished;
}

std::string RunBook::bagPath(const std::string& run_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = runs_.find(run_id);
  if (it == runs_.end() || !it->second.summary) return {};
  const auto& s = *it->second.summary;
  return s.recording_ok ? s.bag_path : std::string();
}

namespace {
const char* stateOf(const WebRun& run) {
  if (run.finished) return "finished";
  return run.record ? "running" : "queued";
}
}  // namespace

std::optional<std::pair<std::string, std::uint64_t>> RunBook::json(const std::string& run_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = runs_.find(run_id);
  if (it == runs_.end()) return std::nullopt;
  const WebRun& run = it->second;
  nlohmann::json out = {{"run_id", run.run_id},
                        {"student", run.student},
                        {"requested_run_id", run.requested_run_id},
                        {"state", stateOf(run)},
                        {"accepted_stamp", run.accepted_stamp},
                        {"collisions", run.record ? run.record->collisions() : 0},
                        {"newest_time", run.record ? run.record->newestTime() : 0.0}};
  if (run.record) {
    out["scene"] = sceneJson(run.record->input());
    if (run.record->prediction) out["prediction"] = predictionJson(*run.record->prediction);
    out["plots"] = plotsJson(*run.record, run.predicted);
  }
  if (run.summary) out["summary"] = summaryJson(*run.summary);
  if (!run.bag_error.empty()) out["bag_error"] = run.bag_error;
  return std::make_pair(out.dump(), run.version);
}

std::pair<std::uint64_t, bool> RunBook::waitForChange(const std::string& run_id, std::uint64_t seen,
                                                      std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  auto current = [&]() -> std::pair<std::uint64_t, bool> {
    auto it = runs_.find(run_id);
    if (it == runs_.end()) return {0, false};
    return {it->second.version, it->second.finished};
  };
  changed_.wait_for(lock, timeout, [&] { return current().first != seen; });
  return current();
}

std::string RunBook::list(const std::optional<std::string>& student) const {
  std::lock_guard<std::mutex> lock(mutex_);
  nlohmann::json out = nlohmann::json::array();
  for (const auto& run_id : order_) {
    const WebRun& run = runs_.at(run_id);
    if (student && run.student != *student) continue;
    nlohmann::json item = {{"run_id", run.run_id},
                           {"student", run.student},
                           {"state", stateOf(run)},
                           {"accepted_stamp", run.accepted_stamp},
                           {"collisions", run.summary ? run.summary->collision_count
                                                      : (run.record ? run.record->collisions() : 0)}};
    if (run.record) item["bodies"] = run.record->bodies();
    if (run.summary) {
      item["model"] = run.summary->model_name;
      item["truncated"] = static_cast<bool>(run.summary->truncated);
    }
    out.push_back(item);
  }
  return out.dump();
}

BagRun readRunFromBag(const std::string& bag_path, std::size_t envelope_vertices) {
  BagRun run;
  const collision_lab_ros::ReadableBag bag = collision_lab_ros::openBagForReading(bag_path);
  rosbag::View view(*bag);
  std::optional<collision_lab::Prediction> prediction;
  RecordLimits limits;
  limits.envelope_vertices = envelope_vertices;
  for (const rosbag::MessageInstance& m : view) {
    if (auto input = m.instantiate<collision_lab::InitialConditions>()) {
      if (run.record) continue;
      run.record = std::make_unique<RunRecord>(*input, limits);
      run.predicted.assign(run.record->plottedBodies().size(), Envelope(envelope_vertices));
      if (prediction) run.record->prediction = *prediction;
    } else if (auto p = m.instantiate<collision_lab::Prediction>()) {
      prediction = *p;
      if (run.record) run.record->prediction = *p;
    } else if (auto e = m.instantiate<collision_lab::CollisionEvent>()) {
      if (!run.record) continue;
      run.record->add(*e);
      addPredicted(run.predicted, *run.record, *e);
    } else if (auto s = m.instantiate<collision_lab::RunSummary>()) {
      if (run.record) run.record->summary = *s;
    }
  }
  return run;
}

std::string htmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace collision_lab_web
