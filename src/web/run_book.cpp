#include "collision_lab/web/run_book.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <set>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/core/totals.h"
#include "collision_lab/ros/bag_csv.h"
#include "collision_lab/ros/bag_reading.h"
#include "collision_lab/ros/run_index_recorder.h"
#include "collision_lab/ros/run_view.h"

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

json points(const Envelope& envelope) {
  json out = json::array();
  for (const auto& v : envelope.polyline()) out.push_back(json::array({number(v.x), number(v.y)}));
  return out;
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

/// The one summary JSON (collision_lab_ros::summaryFields), less bag_path: a path on the
/// lab machine (the page links the run's files instead).
json summaryJson(const collision_lab::RunSummary& s) {
  json out = collision_lab_ros::summaryFields(s);
  out.erase("bag_path");
  return out;
}

/// The x-t diagram's lines to the run's end, cut at a ring's seam (RunView's
/// worldlineSegments): [{body, segments: [[[t [s], x [m]], ...], ...]}].
json worldlineSegmentsJson(const RunRecord& record, double end_time) {
  json lines = json::array();
  for (const auto& line : collision_lab_ros::worldlineSegments(record, end_time)) {
    json segments = json::array();
    for (const auto& segment : line.segments) {
      json vertices = json::array();
      for (const auto& [t, x] : segment) vertices.push_back(json::array({number(t), number(x)}));
      segments.push_back(vertices);
    }
    lines.push_back({{"body", line.body}, {"segments", segments}});
  }
  return lines;
}

json totalsJson(const collision_lab::core::Totals& t) {
  return {{"momentum", exactNumber(t.momentum)}, {"kinetic_energy", exactNumber(t.kinetic_energy)}};
}

/// Runs of at most this many bodies get each body's kinetic energy in their totals.
constexpr std::size_t kPerBodyTotalsMaxBodies = 64;

/// The finite masses' momentum [kg m/s], kinetic energy [J], centre-of-mass velocity [m/s]
/// and (kPerBodyTotalsMaxBodies) each body's kinetic energy [J], every one the exact value
/// correctly rounded (core/totals.h): at the start, and at the end by the simulation, the
/// model and the paper's printed formulas, each where its final velocities are known (else
/// null); with the total finite mass [kg] and the centre of mass at the start [m].
json totalsJson(const RunRecord& record, const collision_lab::RunSummary* summary) {
  const auto& masses = record.input().masses;
  const auto at = [&masses](const std::vector<double>& velocities) -> json {
    if (velocities.size() != masses.size()) return nullptr;
    for (std::size_t i = 0; i < masses.size(); ++i) {
      if (std::isfinite(masses[i]) && !std::isfinite(velocities[i])) return nullptr;
    }
    json totals = totalsJson(collision_lab::core::totalsOf(masses, velocities));
    const std::vector<double> origin(masses.size(), 0.0);
    totals["centre_of_mass_velocity"] = exactNumber(collision_lab::core::centreOfMass(masses, origin, velocities).velocity);
    if (masses.size() <= kPerBodyTotalsMaxBodies) {
      json each = json::array();
      for (double k : collision_lab::core::kineticEnergies(masses, velocities)) each.push_back(exactNumber(k));
      totals["kinetic_per_body"] = std::move(each);
    }
    return totals;
  };
  std::vector<double> paper;
  for (std::size_t i = 0; i < masses.size() && !record.plottedBodies().empty(); ++i) {
    if (record.paperVelocity(i).empty()) break;
    paper.push_back(record.paperVelocity(i).last().y);
  }
  const auto centre = collision_lab::core::centreOfMass(masses, record.input().positions, record.input().velocities);
  return {{"finite_mass", exactNumber(centre.mass)},
          {"centre_of_mass_start", exactNumber(centre.position)},
          {"start", at(record.input().velocities)},
          {"simulated", summary && summary->simulated ? at(summary->final_velocities) : json(nullptr)},
          {"predicted", record.prediction ? at(record.prediction->final_velocities) : json(nullptr)},
          {"paper", at(paper)}};
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
  plots["momentum"] = points(record.momentum());
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

RunBook::RunBook(std::size_t envelope_vertices)
    : RunBook(
          [envelope_vertices] {
            RunBookOptions options;
            options.envelope_vertices = envelope_vertices;
            return options;
          }(),
          nullptr) {}

RunBook::RunBook(const RunBookOptions& options, std::shared_ptr<const RunSource> source)
    : options_(options), source_(std::move(source)) {
  for (std::size_t k = 0; k < std::max<std::size_t>(1, options_.rebuild_threads); ++k) {
    rebuilders_.emplace_back(&RunBook::rebuildLoop, this);
  }
  if (source_ && options_.reconcile_period.count() > 0) reconciler_ = std::thread(&RunBook::reconcileLoop, this);
}

RunBook::~RunBook() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  rebuild_wanted_.notify_all();
  if (reconciler_.joinable()) reconciler_.join();
  for (std::thread& rebuilder : rebuilders_) rebuilder.join();
}

namespace {

/// Heap bytes of a map node and its key beside the value [bytes] (libstdc++: 4 words).
constexpr std::size_t kMapNodeBytes = 4 * sizeof(void*);

std::size_t doublesBytes(const std::vector<double>& v) { return v.capacity() * sizeof(double); }

std::size_t summaryBytes(const collision_lab::RunSummary& s) {
  return s.run_id.capacity() + s.student.capacity() + s.requested_run_id.capacity() + s.model_name.capacity() +
         s.model_reason.capacity() + s.truncation_reason.capacity() + s.stop_reason.capacity() +
         s.bag_path.capacity() + s.recording_error.capacity() + doublesBytes(s.final_velocities);
}

std::size_t eventBytes(const collision_lab::CollisionEvent& e) {
  return sizeof e + e.run_id.capacity() + doublesBytes(e.positions) + doublesBytes(e.velocities_before) +
         doublesBytes(e.velocities_after) + doublesBytes(e.energy_transfer) + doublesBytes(e.kinetic_energy_after) +
         doublesBytes(e.predicted_velocities_after) + doublesBytes(e.paper_velocities_after) +
         doublesBytes(e.predicted_energy_transfer) + doublesBytes(e.paper_energy_transfer);
}

/// What a run holds in memory: the record (RunRecord::memoryBytes), the closed-form series,
/// events waiting for the served input, summaries and strings, the map nodes [bytes].
std::size_t footprintOf(const WebRun& run) {
  std::size_t bytes = sizeof(WebRun) + 2 * kMapNodeBytes + sizeof(std::uint64_t) + 2 * run.run_id.capacity() +
                      run.student.capacity() + run.requested_run_id.capacity() + run.bag_error.capacity();
  if (run.record) bytes += run.record->memoryBytes();
  bytes += run.predicted.capacity() * sizeof(Envelope);
  for (const Envelope& e : run.predicted) bytes += e.memoryBytes();
  bytes += (run.early_events.capacity() - run.early_events.size()) * sizeof(collision_lab::CollisionEvent);
  for (const auto& e : run.early_events) bytes += eventBytes(e);
  if (run.early_prediction) bytes += run.early_prediction->model_name.capacity() + run.early_prediction->model_reason.capacity();
  if (run.pending_summary) bytes += summaryBytes(*run.pending_summary);
  if (run.summary) bytes += summaryBytes(*run.summary);
  return bytes;
}

/// The bag at path, or its ".active" name when only that exists (a run its node left
/// unfinished, not yet recovered).
std::string existingBag(const std::string& path) {
  std::error_code ignored;
  if (path.empty() || std::filesystem::exists(path, ignored)) return path;
  const std::string active = path + ".active";
  return std::filesystem::exists(active, ignored) ? active : path;
}

/// The index's state as the pages name it (as service::runStateName).
const char* stateName(collision_lab::service::RunState state) {
  switch (state) {
    case collision_lab::service::RunState::kQueued: return "queued";
    case collision_lab::service::RunState::kRunning: return "running";
    case collision_lab::service::RunState::kFinished: return "finished";
    case collision_lab::service::RunState::kInterrupted: return "interrupted";
  }
  return "queued";
}

bool ended(collision_lab::service::RunState state) {
  return state == collision_lab::service::RunState::kFinished ||
         state == collision_lab::service::RunState::kInterrupted;
}

/// The summary an index row gives when the run's bag has none (an interrupted run): its
/// stop reason, count and bag, and what its summary_json holds of RunSummary's fields.
/// The run read back from its bag, else why not in `error` ("the run was not recorded"
/// without a bag); the memory the bag took is given back either way.
std::optional<BagRun> readBack(const std::string& bag_path, std::size_t envelope_vertices, std::string& error) {
  std::optional<BagRun> rebuilt;
  try {
    if (bag_path.empty()) throw std::runtime_error("the run was not recorded");
    rebuilt = readRunFromBag(existingBag(bag_path), envelope_vertices);
  } catch (const std::exception& e) {
    error = e.what();
  }
  collision_lab_ros::releaseMemoryAfterBag(bag_path);
  return rebuilt;
}

collision_lab::RunSummary summaryFromRow(const collision_lab::service::IndexedRun& row) {
  collision_lab::RunSummary s;
  const json fields = json::parse(row.summary_json, nullptr, false);
  if (fields.is_object()) {
    try {
      s = collision_lab_ros::summaryFromFields(fields);
    } catch (const json::exception&) {
      s = collision_lab::RunSummary();  // a row some other writer wrote: its columns only
    }
  }
  s.run_id = row.run_id;
  s.student = row.student;
  s.requested_run_id = row.requested_run_id;
  const bool interrupted = row.state == collision_lab::service::RunState::kInterrupted;
  s.stop_reason = row.stop_reason.empty() && interrupted ? "INTERRUPTED" : row.stop_reason;
  s.collision_count = row.collision_count;
  s.bag_path = row.bag_path;
  s.recording_ok = !row.bag_path.empty();
  return s;
}

/// The summary an evicted run's stub gives when its bag has none (an interrupted run).
collision_lab::RunSummary summaryOfStub(const std::string& run_id, const EvictedRun& stub) {
  collision_lab::RunSummary s;
  s.run_id = run_id;
  s.student = stub.student;
  s.requested_run_id = stub.requested_run_id;
  s.model_name = stub.ending.model_name;
  s.collision_count = stub.collision_count;
  s.truncated = stub.ending.truncated;
  s.simulated = stub.ending.simulated;
  s.cancelled = stub.ending.cancelled;
  s.collapsed = stub.ending.collapsed;
  s.truncation_reason = stub.ending.cancel_reason;
  s.stop_reason = stub.interrupted ? "INTERRUPTED" : "";
  s.bag_path = stub.bag_path;
  s.recording_ok = true;
  return s;
}

}  // namespace

WebRun& RunBook::runLocked(const std::string& run_id) {
  auto [it, inserted] = runs_.try_emplace(run_id);
  WebRun& run = it->second;
  if (inserted) {
    run.run_id = run_id;
    run.sequence = next_sequence_++;
    order_[run.sequence] = run_id;
    countLocked(run);
  }
  touchLocked(run);
  return run;
}

void RunBook::touchLocked(WebRun& run) {
  run.touched = std::chrono::steady_clock::now();
  run.last_used = ++use_clock_;
}

void RunBook::countLocked(WebRun& run) {
  resident_bytes_ -= run.footprint;
  run.footprint = footprintOf(run);
  resident_bytes_ += run.footprint;
}

void RunBook::onAccepted(const collision_lab::AcceptedRun& msg) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!evicted_.count(msg.run_id)) {
    WebRun& run = runLocked(msg.run_id);
    run.student = msg.student;
    run.requested_run_id = msg.requested_run_id;
    run.accepted_stamp = msg.header.stamp.toSec();
    ++run.version;
    countLocked(run);
    changed_.notify_all();
  }
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
  if (evicted_.count(msg.run_id)) return;
  WebRun& run = runLocked(msg.run_id);
  if (run.record || run.rebuilding) return;
  RecordLimits limits;
  limits.envelope_vertices = options_.envelope_vertices;
  limits.keep_keyframes = false;  // the web never animates the scene
  run.record = std::make_unique<RunRecord>(msg, limits);
  run.predicted.assign(run.record->plottedBodies().size(), Envelope(options_.envelope_vertices));
  if (run.student.empty()) run.student = msg.student;
  if (run.early_prediction) run.record->prediction = *run.early_prediction;
  run.early_prediction.reset();
  for (const auto& e : run.early_events) {
    run.record->add(e);
    addPredicted(run.predicted, *run.record, e);
  }
  run.early_events = {};
  countLocked(run);
  maybeFinishLocked(run);
  ++run.version;
  changed_.notify_all();
}

void RunBook::onPrediction(const collision_lab::Prediction& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (evicted_.count(msg.run_id)) return;
  WebRun& run = runLocked(msg.run_id);
  if (run.finished || run.rebuilding) return;
  if (run.record) {
    run.record->prediction = msg;
  } else {
    run.early_prediction = msg;
  }
  ++run.version;
  changed_.notify_all();
}

void RunBook::onEvent(const collision_lab::CollisionEvent& msg) {
  /// The footprint of a run in progress is recounted every this many events [1].
  constexpr std::uint64_t kRecountEvery = 256;
  std::lock_guard<std::mutex> lock(mutex_);
  if (evicted_.count(msg.run_id)) return;
  WebRun& run = runLocked(msg.run_id);
  if (run.finished || run.rebuilding) return;
  ++run.events_received;
  if (run.record) {
    run.record->add(msg);
    addPredicted(run.predicted, *run.record, msg);
  } else if (run.early_events.size() < kEarlyEventsKept) {
    run.early_events.push_back(msg);
  }
  if (run.events_received % kRecountEvery == 0) countLocked(run);
  maybeFinishLocked(run);
  ++run.version;
  changed_.notify_all();
}

void RunBook::onProgress(const collision_lab::RunProgress& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (evicted_.count(msg.run_id)) return;
  WebRun& run = runLocked(msg.run_id);
  if (run.finished || run.rebuilding || !run.record) return;
  run.record->addSample(msg.latest_event, msg.energy_lost);
  addPredicted(run.predicted, *run.record, msg.latest_event);  // the closed form's sample too
  ++run.version;
  changed_.notify_all();
}

void RunBook::onSummary(const collision_lab::RunSummary& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (evicted_.count(msg.run_id)) return;
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
  if (!run.record && recorded) return startRebuildLocked(run, summary.bag_path);
  if (!run.record && run.accepted_stamp > 0.0) return;
  // The bag holds every event; the topics stopped at ~max_published_events.
  if (recorded && run.record && summary.events_not_published) return startRebuildLocked(run, summary.bag_path);
  finishLocked(run, summary);
}

void RunBook::finishLocked(WebRun& run, const collision_lab::RunSummary& summary) {
  if (run.record) run.record->summary = summary;
  run.summary = summary;
  run.pending_summary.reset();
  run.early_events = {};
  run.early_prediction.reset();
  run.rebuilding = false;
  run.finished = true;
  countLocked(run);
  enforceBudgetLocked(run.run_id);
}

void RunBook::startRebuildLocked(WebRun& run, const std::string& bag_path) {
  run.rebuilding = true;
  rebuild_queue_.emplace_back(run.run_id, bag_path);
  rebuild_wanted_.notify_one();
}

void RunBook::rebuildLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    rebuild_wanted_.wait(lock, [this] { return stopping_ || !rebuild_queue_.empty(); });
    if (stopping_) return;
    const auto [run_id, bag_path] = rebuild_queue_.front();
    rebuild_queue_.pop_front();
    lock.unlock();
    completeFromBag(run_id, bag_path, std::nullopt);
    lock.lock();
  }
}

void RunBook::completeFromBag(const std::string& run_id, const std::string& bag_path,
                              const std::optional<Completion>& how) {
  std::string error;
  std::optional<BagRun> rebuilt = readBack(bag_path, options_.envelope_vertices, error);
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = runs_.find(run_id);
  if (it == runs_.end() || it->second.finished) return;  // a rebuilding run is never evicted
  WebRun& run = it->second;
  if (rebuilt && rebuilt->record) {
    run.record = std::move(rebuilt->record);
    run.predicted = std::move(rebuilt->predicted);
  } else {
    run.bag_error = error.empty() ? "the bag has no InitialConditions" : error;
  }
  collision_lab::RunSummary summary;
  if (run.pending_summary) {
    summary = *run.pending_summary;
  } else if (run.record && run.record->summary) {
    summary = *run.record->summary;
  } else if (how) {
    summary = how->fallback;
    if (run.record) summary.collision_count = std::max<std::uint64_t>(summary.collision_count, run.record->collisions());
  }
  run.interrupted = how && how->interrupted && !run.pending_summary;
  finishLocked(run, summary);
  touchLocked(run);
  ++run.version;
  changed_.notify_all();
}

bool RunBook::sourceKnows(const std::string& run_id) const {
  if (!source_) return false;
  try {
    const auto row = source_->find(run_id);
    return row && ended(row->state);
  } catch (const std::exception&) {
    return false;
  }
}

void RunBook::enforceBudgetLocked(const std::string& keep) {
  if (resident_bytes_ <= options_.memory_budget_bytes) return;
  std::vector<std::pair<std::uint64_t, std::string>> candidates;  // last_used, run_id
  for (const auto& [run_id, run] : runs_) {
    const bool has_bag = run.summary && run.summary->recording_ok && !run.summary->bag_path.empty();
    if (run.finished && !run.rebuilding && has_bag && run_id != keep) candidates.emplace_back(run.last_used, run_id);
  }
  std::sort(candidates.begin(), candidates.end());
  for (const auto& [last_used, run_id] : candidates) {
    if (resident_bytes_ <= options_.memory_budget_bytes) break;
    auto it = runs_.find(run_id);
    WebRun& run = it->second;
    if (sourceKnows(run_id)) {
      order_.erase(run.sequence);  // the source lists it and gives it back
    } else {
      EvictedRun stub;
      stub.student = run.student;
      stub.requested_run_id = run.requested_run_id;
      stub.accepted_stamp = run.accepted_stamp;
      stub.bag_path = run.summary->bag_path;
      stub.collision_count = run.summary->collision_count;
      stub.bodies = run.record ? static_cast<std::uint32_t>(run.record->bodies()) : 0;
      stub.interrupted = run.interrupted;
      stub.ending = collision_lab_ros::endingOf(*run.summary);
      stub.sequence = run.sequence;
      evicted_.emplace(run_id, std::move(stub));
    }
    resident_bytes_ -= run.footprint;
    runs_.erase(it);
  }
}

bool RunBook::load(const std::string& run_id) {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    auto it = runs_.find(run_id);
    if (it != runs_.end()) {
      it->second.last_used = ++use_clock_;
      return true;
    }
    if (!loading_.count(run_id)) break;
    changed_.wait(lock);  // another caller reads it
  }
  std::optional<EvictedRun> stub;
  if (auto s = evicted_.find(run_id); s != evicted_.end()) stub = s->second;
  loading_.insert(run_id);
  lock.unlock();

  std::optional<collision_lab::service::IndexedRun> row;
  if (!stub && source_) {
    try {
      row = source_->find(run_id);
    } catch (const std::exception&) {
      row.reset();  // unknown for now: the next call asks again
    }
  }
  std::string bag;
  if (stub) bag = stub->bag_path;  // only runs with a bag are evicted
  if (row && ended(row->state)) bag = row->bag_path;
  std::optional<BagRun> rebuilt;
  std::string error;  // a run known to have ended: read back from its bag, or why not
  if (stub || (row && ended(row->state))) rebuilt = readBack(bag, options_.envelope_vertices, error);

  lock.lock();
  loading_.erase(run_id);
  changed_.notify_all();
  if (!stub && !row) return false;
  if (runs_.count(run_id)) return true;  // its messages arrived meanwhile
  auto [it, inserted] = runs_.try_emplace(run_id);
  WebRun& run = it->second;
  run.run_id = run_id;
  run.version = 1;
  if (rebuilt && rebuilt->record) {
    run.record = std::move(rebuilt->record);
    run.predicted = std::move(rebuilt->predicted);
  } else if (!error.empty() || rebuilt) {
    run.bag_error = error.empty() ? "the bag has no InitialConditions" : error;
  }
  if (stub) {
    fillFromStubLocked(run, *stub);
  } else {
    fillFromRowLocked(run, *row);
  }
  if (run.record && run.summary) run.record->summary = run.summary;
  order_[run.sequence] = run_id;
  touchLocked(run);
  countLocked(run);
  enforceBudgetLocked(run_id);
  return true;
}

void RunBook::fillFromStubLocked(WebRun& run, const EvictedRun& stub) {
  run.student = stub.student;
  run.requested_run_id = stub.requested_run_id;
  run.accepted_stamp = stub.accepted_stamp;
  run.interrupted = stub.interrupted;
  run.sequence = stub.sequence;
  if (run.record && run.record->summary && !run.interrupted) {
    run.summary = *run.record->summary;
  } else {
    run.summary = summaryOfStub(run.run_id, stub);
  }
  run.finished = true;
  evicted_.erase(run.run_id);
}

void RunBook::fillFromRowLocked(WebRun& run, const collision_lab::service::IndexedRun& row) {
  run.student = row.student;
  run.requested_run_id = row.requested_run_id;
  run.accepted_stamp = row.accepted_at;
  run.sequence = next_sequence_++;
  run.started = row.state == collision_lab::service::RunState::kRunning;
  if (!ended(row.state)) return;
  run.interrupted = row.state == collision_lab::service::RunState::kInterrupted;
  run.summary = run.record && run.record->summary && !run.interrupted ? *run.record->summary : summaryFromRow(row);
  if (run.interrupted && run.record) {
    run.summary->collision_count = std::max<std::uint64_t>(run.summary->collision_count, run.record->collisions());
  }
  run.finished = true;
}

std::size_t RunBook::reconcile() {
  if (!source_) return 0;
  std::vector<std::string> candidates;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    for (const auto& [run_id, run] : runs_) {
      if (!run.finished && !run.rebuilding && now - run.touched >= options_.reconcile_after) {
        candidates.push_back(run_id);
      }
    }
  }
  std::size_t completed = 0;
  for (const std::string& run_id : candidates) {
    std::optional<collision_lab::service::IndexedRun> row;
    try {
      row = source_->find(run_id);
    } catch (const std::exception&) {
      continue;  // asked again at the next pass
    }
    if (!row || !ended(row->state)) continue;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = runs_.find(run_id);
      if (it == runs_.end() || it->second.finished || it->second.rebuilding) continue;
      it->second.rebuilding = true;  // the topics' late messages are ignored from now on
    }
    Completion how;
    how.interrupted = row->state == collision_lab::service::RunState::kInterrupted;
    how.fallback = summaryFromRow(*row);
    completeFromBag(run_id, row->bag_path, how);
    ++completed;
  }
  return completed;
}

void RunBook::reconcileLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    if (stop_.wait_for(lock, options_.reconcile_period, [this] { return stopping_; })) break;
    lock.unlock();
    reconcile();
    lock.lock();
  }
}

std::size_t RunBook::residentBytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return resident_bytes_;
}

std::size_t RunBook::residentRuns() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return runs_.size();
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
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (runs_.count(run_id) > 0 || evicted_.count(run_id) > 0) return true;
  }
  if (!source_) return false;
  try {
    return source_->find(run_id).has_value();
  } catch (const std::exception&) {
    return false;
  }
}

bool RunBook::resident(const std::string& run_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return runs_.count(run_id) > 0;
}

bool RunBook::finished(const std::string& run_id) const {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = runs_.find(run_id);
    if (it != runs_.end()) return it->second.finished;
    if (evicted_.count(run_id) > 0) return true;
  }
  if (!source_) return false;
  try {
    const auto row = source_->find(run_id);
    return row && ended(row->state);
  } catch (const std::exception&) {
    return false;
  }
}

std::string RunBook::bagPath(const std::string& run_id) const {
  std::optional<collision_lab::RunSummary> summary;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = runs_.find(run_id);
    if (it != runs_.end()) {
      summary = it->second.summary;
    } else if (auto stub = evicted_.find(run_id); stub != evicted_.end()) {
      summary = summaryOfStub(run_id, stub->second);
    }
  }
  if (!summary && source_) {
    try {
      const auto row = source_->find(run_id);
      if (row && ended(row->state)) summary = summaryFromRow(*row);
    } catch (const std::exception&) {
      summary.reset();
    }
  }
  if (!summary || !summary->recording_ok) return {};
  return existingBag(summary->bag_path);
}

namespace {
const char* stateOf(const WebRun& run) {
  if (run.finished) return run.interrupted ? "interrupted" : "finished";
  return run.record || run.started ? "running" : "queued";
}

/// How an ended run ended, for the teacher's list: its model, whether it was simulated,
/// cut short (cancelled: by whom, in cancel_reason), collapsed, and recorded.
void addEnding(nlohmann::json& item, const collision_lab::service::RunEnding& ending, bool recorded) {
  item["model"] = ending.model_name;
  item["truncated"] = ending.truncated;
  item["recorded"] = recorded;
  item["simulated"] = ending.simulated;
  item["collapsed"] = ending.collapsed;
  item["cancelled"] = ending.cancelled;
  if (ending.cancelled) item["cancel_reason"] = ending.cancel_reason;
}

nlohmann::json listItem(const WebRun& run) {
  nlohmann::json item = {{"run_id", run.run_id},
                         {"student", run.student},
                         {"state", stateOf(run)},
                         {"accepted_stamp", run.accepted_stamp},
                         {"collisions", run.summary ? run.summary->collision_count
                                                    : (run.record ? run.record->collisions() : 0)}};
  if (run.record) item["bodies"] = run.record->bodies();
  if (run.summary) {
    addEnding(item, collision_lab_ros::endingOf(*run.summary), run.summary->recording_ok && !run.summary->bag_path.empty());
  }
  return item;
}

nlohmann::json listItem(const std::string& run_id, const EvictedRun& stub) {
  nlohmann::json item = {{"run_id", run_id},
                         {"student", stub.student},
                         {"state", stub.interrupted ? "interrupted" : "finished"},
                         {"accepted_stamp", stub.accepted_stamp},
                         {"collisions", stub.collision_count},
                         {"bodies", stub.bodies}};
  addEnding(item, stub.ending, !stub.bag_path.empty());
  return item;
}

/// A run the web node does not hold, as its index row's columns say.
nlohmann::json listItem(const collision_lab::service::IndexedRun& row) {
  nlohmann::json item = {{"run_id", row.run_id},
                         {"student", row.student},
                         {"state", stateName(row.state)},
                         {"accepted_stamp", row.accepted_at},
                         {"collisions", row.collision_count}};
  if (row.body_count > 0) item["bodies"] = row.body_count;
  if (ended(row.state)) addEnding(item, row.ending, !row.bag_path.empty());
  return item;
}
}  // namespace

std::optional<std::pair<std::string, std::uint64_t>> RunBook::json(const std::string& run_id) {
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (!load(run_id)) return std::nullopt;
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = runs_.find(run_id);
    if (it == runs_.end()) continue;  // evicted between the load and now: load it again
    const WebRun& run = it->second;
    nlohmann::json out = {{"run_id", run.run_id},
                          {"student", run.student},
                          {"requested_run_id", run.requested_run_id},
                          {"state", stateOf(run)},
                          {"accepted_stamp", run.accepted_stamp},
                          {"collisions", run.record ? run.record->collisions() : 0},
                          {"newest_time", run.record ? run.record->newestTime() : 0.0}};
    if (run.record) {
      out["scene"] = collision_lab_ros::inputFields(run.record->input());
      if (run.record->prediction) out["prediction"] = predictionJson(*run.record->prediction);
      out["plots"] = plotsJson(*run.record, run.predicted);
      const auto view = collision_lab_ros::makeRunView(*run.record);
      out["view"] = collision_lab_ros::viewJson(view);
      out["plots"]["worldline_segments"] = worldlineSegmentsJson(*run.record, view.end_time);
    }
    if (run.summary) out["summary"] = summaryJson(*run.summary);
    if (run.record && run.summary) {
      if (run.totals_version != run.version) {
        run.totals_json = totalsJson(*run.record, &*run.summary).dump();
        run.totals_version = run.version;
      }
      out["totals"] = json::parse(run.totals_json);
    }
    if (!run.bag_error.empty()) out["bag_error"] = run.bag_error;
    return std::make_pair(out.dump(), run.version);
  }
  return std::nullopt;
}

std::pair<std::uint64_t, bool> RunBook::waitForChange(const std::string& run_id, std::uint64_t seen,
                                                      std::chrono::milliseconds timeout) {
  load(run_id);  // a stream of a run not in memory: read it back
  std::unique_lock<std::mutex> lock(mutex_);
  auto current = [&]() -> std::pair<std::uint64_t, bool> {
    auto it = runs_.find(run_id);
    if (it == runs_.end()) return {0, evicted_.count(run_id) > 0};
    return {it->second.version, it->second.finished};
  };
  changed_.wait_for(lock, timeout, [&] { return current().first != seen; });
  return current();
}

std::string RunBook::rejections(const std::optional<std::string>& student) const {
  nlohmann::json out = nlohmann::json::array();
  if (!source_) return out.dump();
  std::vector<collision_lab::service::IndexedRejection> rows;
  try {
    rows = source_->rejections(student, kRejectionsListed);
  } catch (const std::exception&) {
    return out.dump();  // the index cannot be read now: the next call asks again
  }
  for (const auto& r : rows) {
    out.push_back({{"at", r.at}, {"student", r.student}, {"run_id", r.run_id}, {"reason_name", r.reason_name},
                   {"field", r.field}, {"message", r.message}});
  }
  return out.dump();
}

std::string RunBook::list(const std::optional<std::string>& student, const ListPage& page) const {
  std::vector<collision_lab::service::IndexedRun> rows;
  if (source_) {
    try {
      rows = source_->list(student);
    } catch (const std::exception&) {
      rows.clear();  // the runs in memory are listed still
    }
  }
  // An entry is its accepted stamp and either its item (a run in memory: its live state)
  // or the index row it is made from; only the page's rows are parsed, outside the lock.
  struct Entry {
    double stamp;
    std::optional<nlohmann::json> item;
    std::size_t row;
  };
  std::vector<Entry> entries;
  entries.reserve(rows.size());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::set<std::string> listed;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      auto it = runs_.find(rows[k].run_id);
      entries.push_back({rows[k].accepted_at,
                         it != runs_.end() ? std::optional<nlohmann::json>(listItem(it->second)) : std::nullopt, k});
      listed.insert(rows[k].run_id);
    }
    // The runs in memory the source does not list (yet), in their order of arrival.
    for (const auto& [sequence, run_id] : order_) {
      if (listed.count(run_id)) continue;
      auto it = runs_.find(run_id);
      if (it != runs_.end()) {
        if (student && it->second.student != *student) continue;
        entries.push_back({it->second.accepted_stamp, listItem(it->second), 0});
      } else if (auto stub = evicted_.find(run_id); stub != evicted_.end()) {
        if (student && stub->second.student != *student) continue;
        entries.push_back({stub->second.accepted_stamp, listItem(run_id, stub->second), 0});
      }
    }
  }
  if (!rows.empty()) {
    std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.stamp < b.stamp; });
  }
  if (page.total) *page.total = entries.size();
  const std::size_t first = std::min(page.offset, entries.size());
  const std::size_t last = first + std::min(page.limit, entries.size() - first);
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = first; k < last; ++k) {
    out.push_back(entries[k].item ? std::move(*entries[k].item) : listItem(rows[entries[k].row]));
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
  limits.keep_keyframes = false;  // the web never animates the scene
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
