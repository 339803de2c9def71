#include "collision_lab/ros/run_record.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_lab/ros/msg_conversion.h"

namespace collision_lab_ros {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// A finished run plays on to this multiple of its last collision's time.
constexpr double kEndMargin = 1.25;
/// The collision index's weight in the time warp: n / (n + kIndexWeightHalf) for n
/// collisions, at most kMaxIndexWeight.
constexpr double kIndexWeightHalf = 50.0, kMaxIndexWeight = 0.85;
/// An auto-timed loop lasts kAutoLoopDuration (1 + log10(1 + n) / kLoopDecades).
constexpr double kLoopDecades = 6.0;

/// Smallest power of two >= value (value > 0 and finite), else 1.
double powerOfTwoAtLeast(double value) {
  if (!(value > 0) || !std::isfinite(value)) return 1.0;
  int exponent = 0;
  const double fraction = std::frexp(value, &exponent);  // value = fraction 2^exponent
  return std::ldexp(1.0, fraction == 0.5 ? exponent - 1 : exponent);
}

/// Largest power of two <= value (value > 0 and finite), else 0.
double powerOfTwoAtMost(double value) {
  if (!(value > 0) || !std::isfinite(value)) return 0.0;
  int exponent = 0;
  std::frexp(value, &exponent);
  return std::ldexp(1.0, exponent - 1);
}

}  // namespace

// ---- Envelope ----

Envelope::Envelope(std::size_t max_vertices)
    : max_vertices_(std::max<std::size_t>(max_vertices, 16)), min_y_(kInf), max_y_(-kInf) {}

void Envelope::add(double x, double y, double mark) {
  x = std::max(x, count_ ? last_.x : 0.0);
  const Vertex v{x, y, mark};
  if (y < min_y_) min_y_ = y;
  if (y > max_y_) max_y_ = y;
  if (columns_.empty() && vertices_.size() < max_vertices_) {
    vertices_.push_back(v);
  } else {
    if (columns_.empty()) switchToColumns(x);
    addToColumns(v);
  }
  last_ = v;
  ++count_;
}

void Envelope::step(double x, double y, double mark) {
  if (count_ == 0) return add(x, y, mark);
  const Vertex held = last_;
  add(x, held.y, held.mark);
  if (!(y == held.y && mark == held.mark)) add(x, y, mark);
}

void Envelope::switchToColumns(double x) {
  const std::size_t n_columns = max_vertices_ / 4;
  // Half the columns used at first, so the run can double before columns merge.
  width_ = powerOfTwoAtLeast(x / static_cast<double>(n_columns / 2));
  columns_.assign(n_columns, Column{});
  std::vector<Vertex> exact;
  exact.swap(vertices_);
  last_ = exact.front();
  addToColumn(static_cast<std::size_t>(last_.x / width_), last_);
  for (std::size_t k = 1; k < exact.size(); ++k) {
    addToColumns(exact[k]);
    last_ = exact[k];
  }
}

void Envelope::addToColumns(const Vertex& v) {
  while (v.x / width_ >= static_cast<double>(columns_.size())) widenColumns();
  const Vertex previous = last_;
  const auto first = static_cast<std::size_t>(previous.x / width_);
  const auto column = static_cast<std::size_t>(v.x / width_);
  // A segment across column boundaries enters each column at its left edge.
  for (std::size_t c = first + 1; c <= column; ++c) {
    const double edge = static_cast<double>(c) * width_;
    const double f = v.x > previous.x ? (edge - previous.x) / (v.x - previous.x) : 1.0;
    const Vertex at_edge{edge, previous.y + f * (v.y - previous.y), std::max(previous.mark, v.mark)};
    addToColumn(c - 1, at_edge);
    addToColumn(c, at_edge);
  }
  addToColumn(column, v);
}

void Envelope::addToColumn(std::size_t c, const Vertex& v) {
  Column& column = columns_[c];
  if (!column.used) {
    column = Column{true, v, v, kInf, -kInf, v.mark};
  }
  column.last = v;
  if (v.y < column.lo) column.lo = v.y;
  if (v.y > column.hi) column.hi = v.y;
  column.mark = std::max(column.mark, v.mark);
}

void Envelope::widenColumns() {
  width_ *= 2;
  const std::size_t n = columns_.size();
  for (std::size_t j = 0; j < n / 2; ++j) {
    const Column& a = columns_[2 * j];
    const Column& b = columns_[2 * j + 1];
    Column merged = a.used ? a : b;
    if (a.used && b.used) {
      merged.last = b.last;
      merged.lo = std::min(a.lo, b.lo);
      merged.hi = std::max(a.hi, b.hi);
      merged.mark = std::max(a.mark, b.mark);
    }
    columns_[j] = merged;
  }
  std::fill(columns_.begin() + static_cast<std::ptrdiff_t>(n / 2), columns_.end(), Column{});
}

std::size_t Envelope::memoryBytes() const {
  return vertices_.capacity() * sizeof(Vertex) + columns_.capacity() * sizeof(Column);
}

std::vector<Envelope::Vertex> Envelope::polyline() const {
  if (columns_.empty()) return vertices_;
  std::vector<Vertex> out;
  const auto push = [&out](const Vertex& v) {
    if (out.empty() || out.back().x != v.x || !(out.back().y == v.y)) out.push_back(v);
  };
  for (const Column& column : columns_) {
    if (!column.used) continue;
    push(column.first);
    // The extremes the line from first to last does not reach, the nearer one first, so
    // a straight segment stays straight and a burst zigzags as little as it can.
    const double middle = (column.first.x + column.last.x) / 2;
    const bool below = column.lo < std::min(column.first.y, column.last.y);
    const bool above = column.hi > std::max(column.first.y, column.last.y);
    const bool low_first = std::abs(column.first.y - column.lo) <= std::abs(column.first.y - column.hi);
    if (below && (low_first || !above)) push({middle, column.lo, column.mark});
    if (above) push({middle, column.hi, column.mark});
    if (below && !low_first && above) push({middle, column.lo, column.mark});
    push(column.last);
  }
  return out;
}

// ---- RunRecord ----

namespace {

/// n evenly spaced indices of 0 .. count - 1, the first and the last included (all when
/// count <= n).
std::vector<std::size_t> evenlySpaced(std::size_t count, std::size_t n) {
  std::vector<std::size_t> out;
  if (count <= n) {
    for (std::size_t i = 0; i < count; ++i) out.push_back(i);
    return out;
  }
  for (std::size_t j = 0; j < n; ++j) out.push_back(j * (count - 1) / (n - 1));
  return out;
}

std::vector<int> slotsOf(const std::vector<std::size_t>& bodies, std::size_t count) {
  std::vector<int> slot(count, -1);
  for (std::size_t k = 0; k < bodies.size(); ++k) slot[bodies[k]] = static_cast<int>(k);
  return slot;
}

}  // namespace

RunRecord::RunRecord(const collision_lab::InitialConditions& input, const RecordLimits& limits)
    : input_(input),
      limits_(limits),
      replay_(input.masses, input.positions, input.velocities, input.ring),
      min_velocity_(kInf),
      max_velocity_(-kInf) {
  // An input of unequal lengths (the node rejects those) is cut to its shortest list.
  const std::size_t n = std::min({input_.masses.size(), input_.positions.size(), input_.velocities.size()});
  input_.masses.resize(n), input_.positions.resize(n), input_.velocities.resize(n);
  limits_.keyframes = std::max<std::size_t>(limits_.keyframes, 8);
  tracked_ = evenlySpaced(n, kMaxTrackedBodies);
  if (n <= kMaxPlottedBodies) plotted_ = evenlySpaced(n, n);
  track_slot_ = slotsOf(tracked_, n);
  plot_slot_ = slotsOf(plotted_, n);
  const Envelope empty(limits_.envelope_vertices);
  velocity_.assign(plotted_.size(), empty);
  paper_velocity_.assign(plotted_.size(), empty);
  body_energy_.assign(plotted_.size(), empty);
  worldline_.assign(tracked_.size(), empty);
  energy_ = momentum_ = energy_lost_ = none_ = empty;
  temperature_ = temperature_fit_ = {};
  temperature_newest_.reset();
  temperature_stride_ = collision_lab::core::temperatureStride(n);
  temperature_fit_bucket_ = 0;
  for (std::size_t i = 0; i < n; ++i) widenVelocityRange(input_.velocities[i]);
  for (std::size_t k = 0; k < plotted_.size(); ++k) {
    const std::size_t i = plotted_[k];
    velocity_[k].add(0.0, input_.velocities[i]);
    body_energy_[k].add(0.0, replay_.kinetic(i));
  }
  for (std::size_t k = 0; k < tracked_.size(); ++k) worldline_[k].add(0.0, input_.positions[tracked_[k]]);
  if (plotted_.empty()) {
    tracked_velocity_.assign(tracked_.size(), empty);
    for (std::size_t k = 0; k < tracked_.size(); ++k) tracked_velocity_[k].add(0.0, input_.velocities[tracked_[k]]);
  }
  start_energy_ = replay_.totalKineticEnergy();
  energy_.add(0.0, start_energy_);
  momentum_.add(0.0, replay_.momentum());
  energy_lost_.add(0.0, 0.0);
  for (double m : input_.masses) {
    if (std::isfinite(m)) finite_mass_ += m, ++finite_bodies_;
  }
  temperature_.add({0, 0.0, temperatureNow()});
  temperature_fit_.add({0, 0.0, temperatureNow()});
}

bool RunRecord::isWall(std::size_t i) const { return i < bodies() && replay_.isWall(i); }

const Envelope& RunRecord::seriesOf(const std::vector<Envelope>& series, const std::vector<int>& slot,
                                    std::size_t i) const {
  const bool kept = i < slot.size() && slot[i] >= 0 && static_cast<std::size_t>(slot[i]) < series.size();
  return kept ? series[static_cast<std::size_t>(slot[i])] : none_;
}

std::size_t RunRecord::keyframeLimit() const {
  const std::size_t by_values = limits_.keyframe_values / std::max<std::size_t>(bodies(), 1);
  return std::max<std::size_t>(8, std::min(limits_.keyframes, by_values));
}

bool RunRecord::keeps(const Keyframe& frame) const {
  if (keyframes_.empty() || frame.index == keyframes_.front().index || frame.index % stride_ == 0) return true;
  return bucket_ > 0 && std::floor(frame.time / bucket_) > std::floor(frame.previous_time / bucket_);
}

void RunRecord::prune() {
  while (keyframes_.size() > keyframeLimit()) {
    std::size_t by_index = 0, by_time = 0;
    for (std::size_t k = 1; k + 1 < keyframes_.size(); ++k) {
      const Keyframe& f = keyframes_[k];
      if (f.index % stride_ == 0) ++by_index;
      else ++by_time;
    }
    if (by_index >= by_time || bucket_ == 0) {
      stride_ *= 2;
    } else {
      bucket_ *= 2;
    }
    const Keyframe newest = keyframes_.back();
    keyframes_.pop_back();
    keyframes_.erase(std::remove_if(keyframes_.begin() + 1, keyframes_.end(),
                                    [this](const Keyframe& f) { return !keeps(f); }),
                     keyframes_.end());
    keyframes_.push_back(newest);
  }
}

bool RunRecord::wellFormed(const collision_lab::CollisionEvent& event) const {
  const std::size_t n = bodies();
  if (event.kind == collision_lab::CollisionEvent::KIND_COLLAPSE) {
    return event.first_moved < event.last_moved && event.last_moved < n;
  }
  if (input().ring > 0 && n >= 2 && std::size_t{event.pair_index} + 1 == n) {
    // A ring's seam: body N-1 meets body 0 (BodyStateReplay moves first_moved..N-1, then 0..last_moved).
    return event.first_moved <= event.pair_index && event.last_moved < event.first_moved;
  }
  return std::size_t{event.pair_index} + 1 < n && event.first_moved <= event.pair_index &&
         event.last_moved > event.pair_index && event.last_moved < n;
}

void RunRecord::recordMove(std::size_t body, double time) {
  const double velocity = replay_.velocities()[body];
  widenVelocityRange(velocity);
  if (track_slot_[body] >= 0) {
    const auto slot = static_cast<std::size_t>(track_slot_[body]);
    worldline_[slot].add(time, replay_.position(body, time));
    if (!tracked_velocity_.empty()) tracked_velocity_[slot].step(static_cast<double>(newest_index_), velocity);
  }
}

void RunRecord::widenVelocityRange(double v) {
  if (!std::isfinite(v)) return;
  min_velocity_ = std::min(min_velocity_, v);
  max_velocity_ = std::max(max_velocity_, v);
}

void RunRecord::apply(const collision_lab::CollisionEvent& event) {
  replayEvent(replay_, event);  // it fits: wellFormed
  for (std::size_t k = 0; k < replay_.movedCount(); ++k) recordMove((replay_.firstMoved() + k) % replay_.size(), event.time);
  stepSeries(event);
}

void RunRecord::stepSeries(const collision_lab::CollisionEvent& event) {
  const std::size_t n = bodies();
  const double k = static_cast<double>(newest_index_);
  // The plotted bodies (at most kMaxPlottedBodies) have a step at every event.
  for (std::size_t slot = 0; slot < plotted_.size(); ++slot) {
    velocity_[slot].step(k, replay_.velocities()[plotted_[slot]]);
    body_energy_[slot].step(k, replay_.kinetic(plotted_[slot]));
  }
  if (event.paper_velocities_after.size() == n) {
    for (std::size_t slot = 0; slot < plotted_.size(); ++slot) {
      const double paper = event.paper_velocities_after[plotted_[slot]];
      const double simulated = replay_.velocities()[plotted_[slot]];
      if (std::isfinite(paper)) paper_velocity_[slot].step(k, paper, std::abs(paper - simulated));
    }
  }
  energy_.step(k, replay_.totalKineticEnergy());
  momentum_.step(k, replay_.momentum());
  energy_lost_.step(k, replay_.heat());
  const collision_lab::core::TemperatureSample sample{event.index, event.time, temperatureNow()};
  temperature_.add(sample);
  // For the fit, offered as the CLI's sampler offers them (core::TemperatureSampler): every
  // k-th impact and each collapse; the newest otherwise waits (temperatureForFit()). The same
  // samples, so the same Haff fit as the CLI's --temperature-csv. Past the published events
  // (sampled states, addSample) the first state past each multiple of k stands for it.
  const std::uint64_t bucket = event.index / temperature_stride_;
  if (event.kind == collision_lab::CollisionEvent::KIND_COLLAPSE || bucket > temperature_fit_bucket_) {
    temperature_fit_.add(sample);
    temperature_fit_bucket_ = std::max(temperature_fit_bucket_, bucket);
    temperature_newest_.reset();
  } else {
    temperature_newest_ = sample;
  }
}

std::vector<collision_lab::core::TemperatureSample> RunRecord::temperatureForFit() const {
  if (!temperature_newest_) return temperature_fit_.samples();
  collision_lab::core::LogTimeSamples with_newest = temperature_fit_;
  with_newest.add(*temperature_newest_);  // the CLI's sampler sends the last impact at the end
  return with_newest.samples();
}

double RunRecord::temperatureNow() const {
  if (finite_bodies_ == 0 || !(finite_mass_ > 0)) return 0.0;
  const double p = replay_.momentum();
  return std::max(0.0, (2 * replay_.totalKineticEnergy() - p * p / finite_mass_) / static_cast<double>(finite_bodies_));
}

Keyframe RunRecord::snapshot(double time) const {
  Keyframe frame;
  frame.index = newest_index_;
  frame.time = time;
  frame.valid_until = kInf;
  frame.previous_time = previous_time_;
  frame.predicted = newest_predicted_;
  frame.collapse = newest_is_collapse_;
  frame.positions = replay_.positions(time);
  frame.velocities = replay_.velocities();
  return frame;
}

void RunRecord::add(const collision_lab::CollisionEvent& event) {
  if (!wellFormed(event)) {
    ++malformed_;
    return;
  }
  const bool collapse = event.kind == collision_lab::CollisionEvent::KIND_COLLAPSE;
  // A collapse counts no impact: its index is the count before it.
  const std::uint64_t expected = collapse ? newest_index_ : newest_index_ + 1;
  if (event.index < expected || (collapse && event.index == newest_index_ && newest_is_collapse_ && has_newest_)) return;
  missed_ += event.index - expected;
  // The newest kept state is exact up to this event, unless events are missing or the
  // infinitely many impacts of a collapse lie between.
  makeNewest(event, event.index == expected && !collapse);
  apply(event);
  keepNewest(event);
}

void RunRecord::addSample(const collision_lab::CollisionEvent& event, double heat) {
  if (event.index <= newest_index_ && has_newest_) return;
  const std::size_t n = bodies();
  if (!wellFormed(event) || event.positions.size() != n || event.velocities_after.size() != n) {
    ++malformed_;
    return;
  }
  if (!sampled_) sampled_after_ = newest_index_;
  sampled_ = true;
  const bool collapse = event.kind == collision_lab::CollisionEvent::KIND_COLLAPSE;
  const std::uint64_t expected = collapse ? newest_index_ : newest_index_ + 1;
  sampled_collisions_ += event.index - std::min(event.index, expected);
  makeNewest(event, false);
  replay_.restart(event.positions, event.velocities_after, event.time, heat);
  for (std::size_t body : tracked_) recordMove(body, event.time);
  for (double v : event.velocities_after) widenVelocityRange(v);
  stepSeries(event);
  keepNewest(event);
}

void RunRecord::makeNewest(const collision_lab::CollisionEvent& event, bool follows) {
  const bool collapse = event.kind == collision_lab::CollisionEvent::KIND_COLLAPSE;
  if (provisional_) keyframes_.pop_back(), provisional_ = false;
  if (newest_kept_) {
    Keyframe& before = keyframes_.back();
    before.valid_until = follows ? event.time : before.time;
  }
  previous_time_ = has_newest_ ? newest_time_ : 0.0;
  newest_index_ = event.index;
  newest_time_ = event.time;
  newest_is_collapse_ = collapse;
  has_newest_ = true;
  newest_predicted_ = event.predicted_velocities_after;
  if (collapse && collapses_++ < kNamedCollapses) {
    named_collapses_.push_back({event.time, event.position, {event.first_moved, event.last_moved}});
  }
}

void RunRecord::keepNewest(const collision_lab::CollisionEvent& event) {
  if (bucket_ == 0 && event.time > 0) {
    bucket_ = powerOfTwoAtMost(event.time / static_cast<double>(keyframeLimit()));
  }
  Keyframe meta;
  meta.index = event.index;
  meta.time = event.time;
  meta.previous_time = previous_time_;
  newest_kept_ = limits_.keep_keyframes && keeps(meta);
  if (newest_kept_) {
    keyframes_.push_back(snapshot(event.time));
    if (keyframes_.size() > keyframeLimit()) prune();
  }
}

std::size_t RunRecord::memoryBytes() const {
  auto doubles = [](const std::vector<double>& v) { return v.capacity() * sizeof(double); };
  auto sizes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  auto envelopes = [](const std::vector<Envelope>& series) {
    std::size_t bytes = series.capacity() * sizeof(Envelope);
    for (const Envelope& e : series) bytes += e.memoryBytes();
    return bytes;
  };
  std::size_t bytes = sizeof(*this);
  bytes += input_.run_id.capacity() + input_.student.capacity() + input_.header.frame_id.capacity();
  bytes += doubles(input_.masses) + doubles(input_.positions) + doubles(input_.velocities) +
           doubles(input_.restitution);
  // BodyStateReplay: masses, velocities, positions, times and kinetic energies per body,
  // and the moved bodies' before/gained (at most N each).
  bytes += 7 * replay_.size() * sizeof(double);
  for (const Keyframe& f : keyframes_) {
    bytes += sizeof(Keyframe) + doubles(f.positions) + doubles(f.velocities) + doubles(f.predicted);
  }
  bytes += doubles(newest_predicted_) + sizes(tracked_) + sizes(plotted_) + sizes(track_slot_) + sizes(plot_slot_);
  bytes += envelopes(velocity_) + envelopes(paper_velocity_) + envelopes(body_energy_) + envelopes(worldline_) +
           envelopes(tracked_velocity_);
  bytes += energy_.memoryBytes() + momentum_.memoryBytes() + energy_lost_.memoryBytes() + none_.memoryBytes() +
           (temperature_.samples().capacity() + temperature_fit_.samples().capacity()) * sizeof(collision_lab::core::TemperatureSample);
  if (prediction) {
    bytes += prediction->run_id.capacity() + prediction->model_name.capacity() + prediction->model_reason.capacity() +
             doubles(prediction->final_velocities);
  }
  if (summary) {
    bytes += summary->run_id.capacity() + summary->student.capacity() + summary->requested_run_id.capacity() +
             summary->model_name.capacity() + summary->model_reason.capacity() +
             summary->truncation_reason.capacity() + summary->stop_reason.capacity() +
             summary->bag_path.capacity() + summary->recording_error.capacity() + doubles(summary->final_velocities);
  }
  return bytes;
}

const std::vector<Keyframe>& RunRecord::keyframes() const {
  if (has_newest_ && !newest_kept_ && !provisional_) {
    keyframes_.push_back(snapshot(newest_time_));
    provisional_ = true;
  }
  return keyframes_;
}

bool RunRecord::finished() const {
  if (summary) {
    return summary->simulated && !summary->truncated && summary->collision_count == collisions();
  }
  return prediction && !sampled_ && input_.mode == collision_lab::InitialConditions::MODE_FULL &&
         prediction->collision_count_defined && !prediction->infinite_collisions &&
         prediction->collision_count == collisions();
}

// ---- the trajectory shown ----

double freeFlightHorizon(const std::vector<double>& x, const std::vector<double>& v) {
  double horizon = kInf;
  for (std::size_t left = 0; left + 1 < x.size() && left + 1 < v.size(); ++left) {
    // Pair (left, left + 1) closes in when the right-hand body (left) is slower.
    const double closing = v[left + 1] - v[left];
    if (closing > 0) horizon = std::min(horizon, std::max(x[left] - x[left + 1], 0.0) / closing);
  }
  return horizon;
}

namespace {

SceneState initialState(const RunRecord& run) {
  SceneState s;
  s.positions = run.input().positions;
  s.velocities = run.input().velocities;
  return s;
}

SceneState stateOf(const Keyframe& frame) {
  SceneState s;
  s.time = frame.time;
  s.positions = frame.positions;
  s.velocities = frame.velocities;
  s.collisions = frame.index;
  return s;
}

/// Free flight from `from` to time t (exact while no pair meets); on a ring of circumference
/// `ring` [m] (> 0) each position wrapped into [0, ring), as the messages report them.
SceneState flown(SceneState from, double t, double ring) {
  for (std::size_t i = 0; i < from.positions.size(); ++i) {
    double& x = from.positions[i];
    x += from.velocities[i] * (t - from.time);
    if (ring > 0) {
      x = std::fmod(x, ring);
      if (x < 0) x += ring;
      if (x >= ring) x = 0.0;  // -tiny + ring rounds to ring
    }
  }
  from.time = t;
  return from;
}

/// Up to when the free flight from the newest known state is exact [s].
double openEnd(const RunRecord& run, const SceneState& newest) {
  if (run.finished()) return kInf;
  return newest.time + freeFlightHorizon(newest.positions, newest.velocities);
}

/// How long bodies that never meet again are shown flying apart [s].
double flyApartTime(const collision_lab::InitialConditions& input) {
  double gap = 0.0, speed = 0.0;
  for (std::size_t i = 0; i + 1 < input.positions.size(); ++i) gap = std::max(gap, input.positions[i] - input.positions[i + 1]);
  for (double v : input.velocities) speed = std::max(speed, std::abs(v));
  return speed > 0 && gap > 0 ? gap / speed : 1.0;
}

}  // namespace

SceneState stateAt(const RunRecord& run, double t) {
  const auto& frames = run.keyframes();
  t = std::max(t, 0.0);
  const auto after = std::upper_bound(frames.begin(), frames.end(), t,
                                      [](double time, const Keyframe& f) { return time < f.time; });
  SceneState base;
  double valid_until = 0.0;
  if (after == frames.begin()) {
    base = initialState(run);
    valid_until = frames.empty() ? openEnd(run, base)
                                 : std::min(frames.front().time, openEnd(run, base));
  } else {
    base = stateOf(*(after - 1));
    valid_until = after == frames.end() ? openEnd(run, base) : (after - 1)->valid_until;
  }
  if (t <= valid_until) return flown(base, t, run.input().ring);
  // t falls where no exact state is kept: show the nearest instant that is known.
  if (after == frames.end() || t - valid_until <= after->time - t) return flown(base, valid_until, run.input().ring);
  return stateOf(*after);
}

double endTime(const RunRecord& run) {
  const auto& frames = run.keyframes();
  const SceneState newest = frames.empty() ? initialState(run) : stateOf(frames.back());
  if (run.finished() && newest.time > 0) return kEndMargin * newest.time;
  const double horizon = run.finished() ? kInf : freeFlightHorizon(newest.positions, newest.velocities);
  const double end = newest.time + (std::isfinite(horizon) ? horizon : flyApartTime(run.input()));
  return std::max(end, std::numeric_limits<double>::min());
}

TimeWarp::TimeWarp(const RunRecord& run) : end_(collision_lab_ros::endTime(run)) {
  // Weight of the collision index in the warp: none for a handful of collisions, most of
  // the loop for thousands, but never all of it (the sparse phases keep some time).
  const double n = static_cast<double>(run.collisions());
  const double index_weight = std::min(kMaxIndexWeight, n / (n + kIndexWeightHalf));
  times_.push_back(0.0);
  std::vector<double> counts{0.0};
  for (const Keyframe& f : run.keyframes()) {
    if (f.time > end_) break;
    times_.push_back(f.time);
    counts.push_back(static_cast<double>(f.index));
  }
  times_.push_back(end_);
  counts.push_back(counts.back());
  const double total = std::max(counts.back(), 1.0);
  for (std::size_t k = 0; k < times_.size(); ++k) {
    phases_.push_back((1 - index_weight) * times_[k] / end_ + index_weight * counts[k] / total);
  }
}

double TimeWarp::timeAt(double phase) const {
  phase = std::clamp(phase, 0.0, phases_.back());
  const auto hi = std::upper_bound(phases_.begin() + 1, phases_.end() - 1, phase);
  const std::size_t k = static_cast<std::size_t>(hi - phases_.begin());
  const double span = phases_[k] - phases_[k - 1];
  const double f = span > 0 ? (phase - phases_[k - 1]) / span : 1.0;
  return std::min(times_[k - 1] + f * (times_[k] - times_[k - 1]), end_);
}

double TimeWarp::rateAt(double phase) const {
  phase = std::clamp(phase, 0.0, phases_.back());
  const auto hi = std::upper_bound(phases_.begin() + 1, phases_.end() - 1, phase);
  const std::size_t k = static_cast<std::size_t>(hi - phases_.begin());
  const double span = phases_[k] - phases_[k - 1];
  return span > 0 ? (times_[k] - times_[k - 1]) / span : 0.0;
}

double autoLoopDuration(std::uint64_t collisions) {
  return kAutoLoopDuration * (1.0 + std::log10(1.0 + static_cast<double>(collisions)) / kLoopDecades);
}

double simulatedTimeOnTimeline(const ros::Time& now, const ros::Time& start, double timeline_scale) {
  const double scale = std::isfinite(timeline_scale) && timeline_scale > 0 ? timeline_scale : 1.0;
  return std::max((now - start).toSec() / scale, 0.0);
}

double replayedTime(const RunRecord& run, const ros::Time& now) {
  const double scale = run.prediction ? run.prediction->timeline_scale : 0.0;
  return std::max(simulatedTimeOnTimeline(now, run.input().header.stamp, scale), run.newestTime());
}

}  // namespace collision_lab_ros
