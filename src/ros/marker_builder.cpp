#include "collision_lab/ros/marker_builder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <geometry_msgs/Point.h>
#include <std_msgs/ColorRGBA.h>

#include "collision_lab/core/wedge.h"

namespace collision_lab_ros {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

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

std::array<double, 3> toArray3(const boost::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

bool isWall(const collision_lab::InitialConditions& input, int i) { return std::isinf(input.masses[i]); }

}  // namespace

double kineticEnergy(const collision_lab::InitialConditions& input, const std::array<double, 3>& v) {
  double energy = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (!isWall(input, i)) energy += 0.5 * input.masses[i] * v[i] * v[i];
  }
  return energy;
}

double momentum(const collision_lab::InitialConditions& input, const std::array<double, 3>& v) {
  double p = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (!isWall(input, i)) p += input.masses[i] * v[i];
  }
  return p;
}

RunRecord::RunRecord(const collision_lab::InitialConditions& input, const RecordLimits& limits)
    : input_(input), limits_(limits) {
  limits_.keyframes = std::max<std::size_t>(limits_.keyframes, 8);
  const Envelope empty(limits_.envelope_vertices);
  velocity_.fill(empty);
  paper_velocity_.fill(empty);
  worldline_.fill(empty);
  energy_ = momentum_ = empty;
  const auto v0 = toArray3(input.velocities);
  for (int i = 0; i < 3; ++i) {
    velocity_[i].add(0.0, v0[i]);
    worldline_[i].add(0.0, input.positions[i]);
  }
  energy_.add(0.0, kineticEnergy(input, v0));
  momentum_.add(0.0, collision_lab_ros::momentum(input, v0));
}

bool RunRecord::keeps(const Keyframe& frame) const {
  if (frame.index == keyframes_.front().index || frame.index % stride_ == 0) return true;
  return bucket_ > 0 && std::floor(frame.time / bucket_) > std::floor(frame.previous_time / bucket_);
}

void RunRecord::prune() {
  while (keyframes_.size() > limits_.keyframes) {
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

void RunRecord::add(const collision_lab::CollisionEvent& event) {
  const std::uint64_t expected = collisions() + 1;
  if (event.index < expected) return;
  missed_ += event.index - expected;
  Keyframe frame;
  frame.index = event.index;
  frame.time = event.time;
  frame.valid_until = kInf;
  frame.positions = toArray3(event.positions);
  frame.velocities = toArray3(event.velocities_after);
  frame.predicted = toArray3(event.predicted_velocities_after);
  if (!keyframes_.empty()) {
    Keyframe& newest = keyframes_.back();
    frame.previous_time = newest.time;
    newest.valid_until = event.index == expected ? event.time : newest.time;
    if (keyframes_.size() > 1 && !keeps(newest)) keyframes_.pop_back();
  }
  if (bucket_ == 0 && event.time > 0) {
    bucket_ = powerOfTwoAtMost(event.time / static_cast<double>(limits_.keyframes));
  }
  keyframes_.push_back(frame);
  if (keyframes_.size() > limits_.keyframes) prune();

  const double k = static_cast<double>(event.index);
  for (int i = 0; i < 3; ++i) {
    velocity_[i].step(k, frame.velocities[i]);
    worldline_[i].add(event.time, frame.positions[i]);
    const double paper = event.paper_velocities_after[i];
    if (std::isfinite(paper)) paper_velocity_[i].step(k, paper, std::abs(paper - frame.velocities[i]));
  }
  energy_.step(k, event.total_energy);
  momentum_.step(k, event.total_momentum);
}

bool RunRecord::finished() const {
  if (summary) {
    return summary->simulated && !summary->truncated && summary->collision_count == collisions();
  }
  return prediction && input_.mode == collision_lab::InitialConditions::MODE_FULL &&
         prediction->collision_count == collisions();
}

// ---- the trajectory shown ----

double freeFlightHorizon(const std::array<double, 3>& x, const std::array<double, 3>& v) {
  double horizon = kInf;
  for (int left = 0; left < 2; ++left) {
    // Pair (left, left + 1) closes in when the right-hand body (left) is slower.
    const double closing = v[left + 1] - v[left];
    if (closing > 0) horizon = std::min(horizon, std::max(x[left] - x[left + 1], 0.0) / closing);
  }
  return horizon;
}

namespace {

SceneState initialState(const RunRecord& run) {
  SceneState s;
  s.positions = toArray3(run.input().positions);
  s.velocities = toArray3(run.input().velocities);
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

/// Free flight from `from` to time t (exact while no pair meets).
SceneState flown(SceneState from, double t) {
  for (int i = 0; i < 3; ++i) from.positions[i] += from.velocities[i] * (t - from.time);
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
  for (int i = 0; i < 2; ++i) gap = std::max(gap, input.positions[i] - input.positions[i + 1]);
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
  if (t <= valid_until) return flown(base, t);
  // t falls where no exact state is kept: show the nearest instant that is known.
  if (after == frames.end() || t - valid_until <= after->time - t) return flown(base, valid_until);
  return stateOf(*after);
}

double endTime(const RunRecord& run) {
  const auto& frames = run.keyframes();
  const SceneState newest = frames.empty() ? initialState(run) : stateOf(frames.back());
  if (run.finished() && newest.time > 0) return 1.25 * newest.time;
  const double horizon = run.finished() ? kInf : freeFlightHorizon(newest.positions, newest.velocities);
  const double end = newest.time + (std::isfinite(horizon) ? horizon : flyApartTime(run.input()));
  return std::max(end, std::numeric_limits<double>::min());
}

TimeWarp::TimeWarp(const RunRecord& run) : end_(collision_lab_ros::endTime(run)) {
  // Weight of the collision index in the warp: none for a handful of collisions, most of
  // the loop for thousands, but never all of it (the sparse phases keep some time).
  const double n = static_cast<double>(run.collisions());
  const double index_weight = std::min(0.85, n / (n + 50.0));
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
  return kAutoLoopDuration * (1.0 + std::log10(1.0 + static_cast<double>(collisions)) / 6.0);
}

double simulatedTimeOnTimeline(const ros::Time& now, const ros::Time& start, double timeline_scale) {
  const double scale = std::isfinite(timeline_scale) && timeline_scale > 0 ? timeline_scale : 1.0;
  return std::max((now - start).toSec() / scale, 0.0);
}

}  // namespace collision_lab_ros

// ---- drawing ----

namespace collision_lab_ros {

namespace {

using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;
using Vec3 = std::array<double, 3>;
using Polyline = std::vector<Envelope::Vertex>;

/// A rectangle in the marker frame [rviz units].
struct Box {
  double left, right, bottom, top;
  double midX() const { return (left + right) / 2; }
  double midY() const { return (bottom + top) / 2; }
};

// Layout [rviz units]. rviz/collision_lab.rviz looks down at (2.8, 0.85), 46 px per unit;
// its 1248 x 708 pixel view shows x in [-10.7, 16.3] and y in [-6.8, 8.5].
constexpr double kCentreX = 2.8;
constexpr double kTitleY = 8.25, kNoteY = 7.8, kStatusY = 7.35, kVelocityRowY = 6.9;
constexpr double kSceneY = 6.05, kSceneLeft = -10.2, kSceneRight = 15.8, kZoomY = 5.05;
constexpr double kPanelTitleY = 4.55, kLegendY = 4.2;
constexpr Box kWedgeBox{-10.6, -4.6, -0.55, 3.65};
constexpr double kWedgeRadius = 2.1;
constexpr Box kBarsBox{-9.9, -5.3, -6.3, -2.6};
constexpr Box kVelocityBox{-2.2, 5.2, -0.35, 3.55};
constexpr Box kEnergyBox{-2.2, 5.2, -3.05, -1.55};
constexpr Box kMomentumBox{-2.2, 5.2, -6.1, -4.6};
constexpr Box kWorldBox{8.3, 15.9, -6.1, 3.55};
constexpr double kTextSize = 0.32, kSmallTextSize = 0.29, kTitleSize = 0.38;
/// B gets its own panel when its largest speed exceeds A's and C's by this factor.
constexpr double kOwnScaleFactor = 5.0;
/// The paper's velocities widen a panel's scale at most this much; beyond, they are clipped.
constexpr double kPaperScaleFactor = 4.0;
/// At most this many closed-form dots per series (they sit on the simulated steps).
constexpr std::size_t kMaxPredictedDots = 200;
/// At most this many states per series in the wedge when not every collision is kept.
constexpr std::size_t kMaxWedgeDots = 600;
constexpr const char* kNames[3] = {"A", "B", "C"};

std_msgs::ColorRGBA color(double r, double g, double b, double a = 1.0) {
  std_msgs::ColorRGBA c;
  c.r = r; c.g = g; c.b = b; c.a = a;
  return c;
}
std_msgs::ColorRGBA particleColor(int i, double lighten = 0.0) {
  static const double rgb[3][3] = {{0.95, 0.25, 0.25}, {0.25, 0.8, 0.3}, {0.3, 0.55, 1.0}};
  return color(rgb[i][0] + (1 - rgb[i][0]) * lighten, rgb[i][1] + (1 - rgb[i][1]) * lighten,
               rgb[i][2] + (1 - rgb[i][2]) * lighten);
}
const std_msgs::ColorRGBA kWhite = color(0.95, 0.95, 0.95);
const std_msgs::ColorRGBA kGrey = color(0.6, 0.6, 0.6);
/// Small grey text lighter than lines: rviz draws a minus sign one pixel thin.
const std_msgs::ColorRGBA kLabelGrey = color(0.8, 0.8, 0.8);
const std_msgs::ColorRGBA kAmber = color(1.0, 0.75, 0.2);
const std_msgs::ColorRGBA kPaper = color(1.0, 0.55, 0.9);
const std_msgs::ColorRGBA kPredicted = color(0.8, 0.5, 1.0);

geometry_msgs::Point point(double x, double y, double z = 0.0) {
  geometry_msgs::Point p;
  p.x = x; p.y = y; p.z = z;
  return p;
}

Marker base(const std::string& frame_id, const std::string& ns, int id, int type) {
  Marker m;
  m.header.frame_id = frame_id;  // stamp 0: rviz uses the latest transform
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.color = kWhite;
  return m;
}

Marker text(const std::string& frame_id, const std::string& ns, int id, double x, double y,
            const std::string& s, double size = kTextSize, const std_msgs::ColorRGBA& c = kWhite) {
  Marker m = base(frame_id, ns, id, Marker::TEXT_VIEW_FACING);
  m.pose.position = point(x, y, 0.2);
  m.scale.z = size;
  m.color = c;
  m.text = s;
  return m;
}

Marker lines(const std::string& frame_id, const std::string& ns, int id, int type, double width,
             const std_msgs::ColorRGBA& c) {
  Marker m = base(frame_id, ns, id, type);
  m.scale.x = width;
  m.color = c;
  return m;
}

Marker dots(const std::string& frame_id, const std::string& ns, int id, double size,
            const std_msgs::ColorRGBA& c) {
  Marker m = base(frame_id, ns, id, Marker::SPHERE_LIST);
  m.scale.x = m.scale.y = m.scale.z = size;
  m.color = c;
  return m;
}

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
}

/// 31415 -> "31,415".
std::string withSeparators(std::uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t k = 0; k < digits.size(); ++k) {
    if (k > 0 && (digits.size() - k) % 3 == 0) out += ',';
    out += digits[k];
  }
  return out;
}

/// Line markers go out only with enough points for rviz (>= 2; LINE_LIST in pairs).
void addLines(std::vector<Marker>& out, Marker m) {
  if (m.points.size() >= 2) out.push_back(std::move(m));
}

/// A linear map from data (x in [x0, x1], y in [y0, y1]) into a box; values outside are
/// drawn at its edges.
struct Axes {
  Box box;
  double x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0;
  double toX(double x) const {
    return box.left + std::clamp((x - x0) / (x1 - x0), 0.0, 1.0) * (box.right - box.left);
  }
  double toY(double y) const {
    return box.bottom + std::clamp((y - y0) / (y1 - y0), 0.0, 1.0) * (box.top - box.bottom);
  }
  bool contains(double y) const { return y >= y0 && y <= y1; }
};

/// [lo, hi] widened to include `always` and padded by 6 %; [-1, 1] around it when empty.
std::pair<double, double> paddedRange(double lo, double hi, double always = 0.0) {
  lo = std::min(lo, always);
  hi = std::max(hi, always);
  if (!(hi > lo) || !std::isfinite(hi - lo)) {
    const double centre = std::isfinite(lo) ? lo : 0.0;
    return {centre - 1.0, centre + 1.0};
  }
  const double pad = 0.06 * (hi - lo);
  return {lo - pad, hi + pad};
}

/// The frame, a zero line when 0 is inside, values at the bottom, top and zero, and a
/// label over the panel.
void addFrame(std::vector<Marker>& out, const std::string& frame_id, const std::string& ns, int id,
              const Axes& axes, const std::string& label) {
  const Box& b = axes.box;
  Marker frame = lines(frame_id, ns, id, Marker::LINE_LIST, 0.025, kGrey);
  frame.points = {point(b.left, b.bottom), point(b.right, b.bottom), point(b.left, b.bottom),
                  point(b.left, b.top)};
  if (axes.y0 < 0 && axes.y1 > 0) {
    frame.points.push_back(point(b.left, axes.toY(0.0)));
    frame.points.push_back(point(b.right, axes.toY(0.0)));
  }
  out.push_back(frame);
  // Zero is labelled whenever it is inside; an end label too close to it gives way.
  const double zero = axes.toY(0.0);
  const bool zero_inside = axes.y0 < 0 && axes.y1 > 0;
  if (!zero_inside || b.top - zero > 0.3) {
    out.push_back(text(frame_id, ns, id + 1, b.left - 0.55, b.top, format("%.3g", axes.y1), kSmallTextSize));
  }
  if (!zero_inside || zero - b.bottom > 0.3) {
    out.push_back(text(frame_id, ns, id + 2, b.left - 0.55, b.bottom, format("%.3g", axes.y0), kSmallTextSize));
  }
  if (zero_inside) out.push_back(text(frame_id, ns, id + 3, b.left - 0.3, zero, "0", kSmallTextSize));
  out.push_back(text(frame_id, ns, id + 4, b.midX(), b.top + 0.22, label, kSmallTextSize));
}

/// A series as one LINE_STRIP (x along the box's x); non-finite vertices are skipped.
Marker strip(const std::string& frame_id, const std::string& ns, int id, const Polyline& poly,
             const Axes& axes, const std_msgs::ColorRGBA& c, double width = 0.035) {
  Marker m = lines(frame_id, ns, id, Marker::LINE_STRIP, width, c);
  for (const auto& v : poly) {
    if (std::isfinite(v.x) && std::isfinite(v.y)) m.points.push_back(point(axes.toX(v.x), axes.toY(v.y)));
  }
  return m;
}

/// A series' steps as a LINE_STRIP, plus a dot at its start when the known part is too
/// short to see on the axis (a run whose collisions are not shown one by one).
void addSeries(std::vector<Marker>& out, const std::string& frame_id, const std::string& ns, int id,
               const Polyline& poly, const Axes& axes, const std_msgs::ColorRGBA& c, double width = 0.035) {
  addLines(out, strip(frame_id, ns, id, poly, axes, c, width));
  if (!poly.empty() && axes.toX(poly.back().x) - axes.toX(poly.front().x) < 0.1) {
    Marker dot = dots(frame_id, ns, id + 1000, 0.16, c);
    dot.points.push_back(point(axes.toX(poly.front().x), axes.toY(poly.front().y), 0.05));
    out.push_back(dot);
  }
}

/// The segments of a series whose mark exceeds `tolerance`, as a LINE_LIST.
Marker markedSegments(const std::string& frame_id, const std::string& ns, int id, const Polyline& poly,
                      const Axes& axes, double tolerance, const std_msgs::ColorRGBA& c) {
  Marker m = lines(frame_id, ns, id, Marker::LINE_LIST, 0.025, c);
  for (std::size_t k = 1; k < poly.size(); ++k) {
    const auto& a = poly[k - 1];
    const auto& b = poly[k];
    if (!(std::isfinite(a.y) && std::isfinite(b.y))) continue;
    if (!(std::max(a.mark, b.mark) > tolerance)) continue;
    m.points.push_back(point(axes.toX(a.x), axes.toY(a.y), 0.02));
    m.points.push_back(point(axes.toX(b.x), axes.toY(b.y), 0.02));
  }
  return m;
}

/// The series' polyline held at its last value up to x_end.
Polyline withTail(const Envelope& e, double x_end) {
  Polyline poly = e.polyline();
  if (!poly.empty() && x_end > poly.back().x) poly.push_back({x_end, e.last().y, e.last().mark});
  return poly;
}

/// Evenly thinned keyframes, at most `n`.
std::vector<const Keyframe*> thinned(const std::vector<Keyframe>& frames, std::size_t n) {
  std::vector<const Keyframe*> out;
  const std::size_t stride = std::max<std::size_t>(1, (frames.size() + n - 1) / n);
  for (std::size_t k = 0; k < frames.size(); k += stride) out.push_back(&frames[k]);
  return out;
}

// ---- what kind of run ----

/// Collisions the run is known to have, as far as the messages tell [1].
std::uint64_t expectedCollisions(const RunRecord& run) {
  if (run.summary && run.summary->simulated && !run.summary->truncated) return run.summary->collision_count;
  if (run.prediction) return std::max<std::uint64_t>(run.prediction->collision_count, run.collisions());
  return run.collisions();
}

bool simulatedStepByStep(const RunRecord& run) {
  return run.input().mode == collision_lab::InitialConditions::MODE_FULL &&
         !(run.summary && !run.summary->simulated);
}

/// The collision index axis runs to this [1]: one past the last drawn step, or past the
/// predicted count when the collisions are not shown one by one.
double indexAxisEnd(const RunRecord& run) {
  const std::uint64_t n = simulatedStepByStep(run) ? run.collisions() : expectedCollisions(run);
  return static_cast<double>(n) + 1.0;
}

/// Velocities after all the collisions when the steps do not get there: the summary's
/// (simulated or, when not simulated, predicted) or the prediction's, at index n.
std::optional<std::pair<std::uint64_t, Vec3>> finalVelocitiesNotDrawn(const RunRecord& run) {
  if (simulatedStepByStep(run) && !(run.summary && run.summary->truncated)) return std::nullopt;
  if (run.summary && run.summary->simulated && !run.summary->truncated) {
    return std::make_pair(run.summary->collision_count, toArray3(run.summary->final_velocities));
  }
  if (run.prediction && run.prediction->collision_count > run.collisions()) {
    return std::make_pair(run.prediction->collision_count, toArray3(run.prediction->final_velocities));
  }
  return std::nullopt;
}

std::string runTitle(const RunRecord& run) {
  std::string title = "run " + run.input().run_id;
  if (run.prediction) {
    title += ":  predicted " + withSeparators(run.prediction->collision_count) + " collisions";
    title += run.prediction->paper_count_defined
                 ? "  (paper's eq. 3.22: " + std::to_string(run.prediction->paper_collision_count) + ")"
                 : "  (paper's eq. 3.22: undefined)";
  }
  if (run.summary) {
    title += run.summary->simulated ? ",  simulated " + withSeparators(run.summary->collision_count)
                                    : ",  not simulated";
    if (run.summary->truncated) title += " (truncated)";
  }
  return title;
}

/// What the picture does not show, in one line (empty when it shows the whole run).
std::string runNote(const RunRecord& run) {
  std::string note;
  if (run.missedCollisions() > 0) {
    note += withSeparators(run.missedCollisions()) + " collision messages missing; ";
  }
  if (run.summary && run.summary->truncated) {
    note += "stopped: " + run.summary->truncation_reason + ". Shown up to the last known state.";
  } else if (run.input().mode == collision_lab::InitialConditions::MODE_PREDICT_ONLY) {
    note += "predict-only run: shown up to the first contact; the plots show the closed form's final velocities.";
  } else if (run.input().mode == collision_lab::InitialConditions::MODE_SUMMARY_ONLY) {
    note += "summary-only run: shown up to the first contact; the plots show the final velocities.";
  } else if (!run.finished()) {
    note += "run in progress: shown up to the last collision received.";
  }
  return note;
}

// ---- scene ----

struct SceneAxis {
  double min = 0.0, max = 1.0;
  double toX(double position) const {
    return kSceneLeft + (position - min) / (max - min) * (kSceneRight - kSceneLeft);
  }
};

/// Every position the animation can show: the worldlines and the end state.
SceneAxis sceneAxis(const RunRecord& run) {
  double lo = kInf, hi = -kInf;
  for (int i = 0; i < 3; ++i) {
    lo = std::min(lo, run.worldline(i).minY());
    hi = std::max(hi, run.worldline(i).maxY());
  }
  for (double x : stateAt(run, endTime(run)).positions) {
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  const auto [min, max] = paddedRange(lo, hi, lo);
  return {min, max};
}

double bodyDiameter(const collision_lab::InitialConditions& input, int i) {
  double lo = kInf, hi = 0.0;
  for (int j = 0; j < 3; ++j) {
    if (!isWall(input, j)) lo = std::min(lo, input.masses[j]), hi = std::max(hi, input.masses[j]);
  }
  const double decades = std::max(std::log10(hi / lo), 1.0);
  return 0.35 + 0.55 * std::log10(input.masses[i] / lo) / decades;
}

void addSceneAxis(std::vector<Marker>& out, const RunRecord& run, const std::string& frame_id) {
  Marker axis = lines(frame_id, "scene", 0, Marker::LINE_LIST, 0.03, kGrey);
  axis.points = {point(kSceneLeft, kSceneY), point(kSceneRight, kSceneY)};
  out.push_back(axis);
  const SceneAxis scene = sceneAxis(run);
  out.push_back(text(frame_id, "scene", 1, kSceneLeft + 0.9, kSceneY - 0.5, format("x = %.4g m", scene.min),
                     kSmallTextSize, kLabelGrey));
  out.push_back(text(frame_id, "scene", 2, kSceneRight - 0.9, kSceneY - 0.5, format("x = %.4g m", scene.max),
                     kSmallTextSize, kLabelGrey));
  const std::string note = runNote(run);
  if (!note.empty()) out.push_back(text(frame_id, "scene", 4, kCentreX, kNoteY, note, kTextSize, kAmber));
}

// ---- velocity space ----

/// The plane s-perp of mass-weighted velocity space u = S v, seen in the core's wedge
/// basis (r_BC, n_BC) (core/wedge.h), so that the angle of a point is the paper's psi and
/// the ray r_AB lies at +alpha. A wall is the m -> inf limit: its axis is s.
class WedgeFrame {
 public:
  explicit WedgeFrame(const collision_lab::InitialConditions& input)
      : input_(input), wedge_(collision_lab::core::wedgeOf<double>(toArray3(input.masses))) {
    for (int i = 0; i < 3; ++i) {
      if (isWall(input, i)) wall_ = i;
    }
  }

  /// u_perp of velocities v [m/s] as (r_BC, n_BC) coordinates [sqrt(kg) m/s].
  std::array<double, 2> project(const Vec3& v) const {
    double reference = 0.0;
    if (wall_ >= 0) {
      reference = v[wall_];
    } else {
      double p = 0.0, m = 0.0;
      for (int i = 0; i < 3; ++i) p += input_.masses[i] * v[i], m += input_.masses[i];
      reference = p / m;
    }
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) u[i] = i == wall_ ? 0.0 : std::sqrt(input_.masses[i]) * (v[i] - reference);
    return wedge_.coordinates(u);
  }

  /// Angle of r_AB from r_BC: the cone's opening, alpha [rad].
  double abAngle() const { return wedge_.alpha; }

 private:
  const collision_lab::InitialConditions& input_;
  collision_lab::core::Wedge<double> wedge_;
  int wall_ = -1;
};

const double kWedgeX = kWedgeBox.midX(), kWedgeY = kWedgeBox.midY();

/// Scale from u_perp to rviz units: |u_perp| is conserved, so the path lies on a circle.
double wedgeScale(const WedgeFrame& frame, const RunRecord& run) {
  const auto u0 = frame.project(toArray3(run.input().velocities));
  const double r = std::hypot(u0[0], u0[1]);
  return r > 0 ? 0.8 * kWedgeRadius / r : 1.0;
}

geometry_msgs::Point wedgePoint(const std::array<double, 2>& u, double scale, double z = 0.0) {
  return point(kWedgeX + scale * u[0], kWedgeY + scale * u[1], z);
}

void addWedgeGeometry(std::vector<Marker>& out, double a, const std::string& frame_id) {
  Marker cone = base(frame_id, "wedge", 0, Marker::TRIANGLE_LIST);
  cone.color = color(1.0, 0.85, 0.2, 0.3);
  constexpr int kSegments = 32;
  for (int k = 0; k < kSegments; ++k) {
    const double a0 = a * k / kSegments, a1 = a * (k + 1) / kSegments;
    cone.points.push_back(point(kWedgeX, kWedgeY, -0.01));
    cone.points.push_back(point(kWedgeX + kWedgeRadius * std::cos(a0), kWedgeY + kWedgeRadius * std::sin(a0), -0.01));
    cone.points.push_back(point(kWedgeX + kWedgeRadius * std::cos(a1), kWedgeY + kWedgeRadius * std::sin(a1), -0.01));
  }
  out.push_back(cone);
  Marker l = lines(frame_id, "wedge", 1, Marker::LINE_LIST, 0.03, kWhite);
  for (double angle : {0.0, a}) {
    l.points.push_back(point(kWedgeX - kWedgeRadius * std::cos(angle), kWedgeY - kWedgeRadius * std::sin(angle)));
    l.points.push_back(point(kWedgeX + kWedgeRadius * std::cos(angle), kWedgeY + kWedgeRadius * std::sin(angle)));
  }
  out.push_back(l);
  out.push_back(text(frame_id, "wedge", 2, kWedgeX + 1.14 * kWedgeRadius, kWedgeY, "L_BC", kSmallTextSize));
  out.push_back(text(frame_id, "wedge", 3, kWedgeX + 1.14 * kWedgeRadius * std::cos(a),
                     kWedgeY + 1.14 * kWedgeRadius * std::sin(a) + (a < 0.3 ? 0.35 : 0.0), "L_AB",
                     kSmallTextSize));
  Marker circle = lines(frame_id, "wedge", 5, Marker::LINE_STRIP, 0.012, kGrey);
  for (int k = 0; k <= 96; ++k) {
    const double angle = 2 * M_PI * k / 96;
    circle.points.push_back(point(kWedgeX + 0.8 * kWedgeRadius * std::cos(angle),
                                  kWedgeY + 0.8 * kWedgeRadius * std::sin(angle)));
  }
  out.push_back(circle);
}

void addWedge(std::vector<Marker>& out, const RunRecord& run, const std::string& frame_id) {
  const WedgeFrame wedge(run.input());
  const double scale = wedgeScale(wedge, run);
  addWedgeGeometry(out, wedge.abAngle(), frame_id);
  const auto& frames = run.keyframes();
  // The path joins consecutive states only while every collision is kept.
  const bool every_collision = frames.size() == run.collisions() && run.missedCollisions() == 0;
  Marker path = lines(frame_id, "wedge", 6, Marker::LINE_STRIP, 0.025, color(1.0, 0.55, 0.1, 0.8));
  Marker sim = dots(frame_id, "wedge", 7, 0.16, color(1.0, 0.55, 0.1));
  Marker pred = dots(frame_id, "wedge", 8, 0.08, kPredicted);
  const auto start = wedgePoint(wedge.project(toArray3(run.input().velocities)), scale);
  path.points.push_back(start);
  sim.points.push_back(start);
  if (every_collision) {
    for (const Keyframe& f : frames) path.points.push_back(wedgePoint(wedge.project(f.velocities), scale));
  }
  // Spheres are costly in rviz: at most kMaxWedgeDots of them per series.
  const auto shown = thinned(frames, kMaxWedgeDots);
  for (const Keyframe* f : shown) {
    sim.points.push_back(wedgePoint(wedge.project(f->velocities), scale));
    pred.points.push_back(wedgePoint(wedge.project(f->predicted), scale, 0.05));
  }
  addLines(out, path);
  out.push_back(sim);
  if (!pred.points.empty()) out.push_back(pred);
  out.push_back(text(frame_id, "wedge", 9, start.x, start.y - 0.3, "start", kSmallTextSize));
  out.push_back(text(frame_id, "wedge", 10, kWedgeX, kPanelTitleY, "velocity space s-perp (u = S v)", kTextSize));
  out.push_back(text(frame_id, "wedge", 4, kWedgeX, kWedgeBox.bottom - 0.1,
                     "yellow: escape cone, alpha = " + format("%.4g rad", wedge.abAngle()), kSmallTextSize,
                     color(1.0, 0.85, 0.2)));
  const std::string which = shown.size() == run.collisions()
                                ? "each collision"
                                : withSeparators(shown.size()) + " of " + withSeparators(run.collisions()) + " collisions";
  out.push_back(text(frame_id, "wedge", 11, kWedgeX, kWedgeBox.bottom - 0.65,
                     "orange: u_perp after " + which + "\nviolet: closed form", kSmallTextSize));
}

// ---- velocity against collision index ----

struct VelocityPanel {
  Axes axes;
  std::vector<int> bodies;
};

double largestSpeed(const Envelope& e) { return std::max(std::abs(e.minY()), std::abs(e.maxY())); }

/// One panel for all three, or B on its own (top) when it dwarfs A and C.
std::vector<VelocityPanel> velocityPanels(const RunRecord& run) {
  const auto final_v = finalVelocitiesNotDrawn(run);
  const auto bounds = [&](const std::vector<int>& bodies) {
    double lo = kInf, hi = -kInf;
    for (int i : bodies) {
      lo = std::min(lo, run.velocity(i).minY());
      hi = std::max(hi, run.velocity(i).maxY());
      if (final_v && std::isfinite(final_v->second[i])) {
        lo = std::min(lo, final_v->second[i]), hi = std::max(hi, final_v->second[i]);
      }
    }
    // The paper's values join the scale unless they would squash the simulated ones.
    double paper_lo = lo, paper_hi = hi;
    for (int i : bodies) {
      paper_lo = std::min(paper_lo, run.paperVelocity(i).minY());
      paper_hi = std::max(paper_hi, run.paperVelocity(i).maxY());
    }
    if (paper_hi - paper_lo <= kPaperScaleFactor * (hi - lo)) lo = paper_lo, hi = paper_hi;
    return paddedRange(lo, hi);
  };
  const double x1 = indexAxisEnd(run);
  const auto panel = [&](const Box& box, const std::vector<int>& bodies) {
    const auto [y0, y1] = bounds(bodies);
    return VelocityPanel{Axes{box, 0.0, x1, y0, y1}, bodies};
  };
  const double others = std::max(largestSpeed(run.velocity(0)), largestSpeed(run.velocity(2)));
  if (largestSpeed(run.velocity(1)) > kOwnScaleFactor * others) {
    const double gap = 0.45, middle = kVelocityBox.midY();
    return {panel({kVelocityBox.left, kVelocityBox.right, middle + gap / 2, kVelocityBox.top}, {1}),
            panel({kVelocityBox.left, kVelocityBox.right, kVelocityBox.bottom, middle - gap / 2}, {0, 2})};
  }
  return {panel(kVelocityBox, {0, 1, 2})};
}

/// Step k (the velocities after k collisions) spans [k, k+1] of the axis; its label sits
/// under its middle: every step while there are few, else the first and the last. (The
/// panels' titles name the axis.)
void addIndexAxisLabels(std::vector<Marker>& out, const std::string& frame_id, const std::string& ns,
                        int id, const Axes& axes) {
  constexpr std::uint64_t kAllLabelsUpTo = 12;
  const auto last = static_cast<std::uint64_t>(axes.x1) - 1;
  std::vector<std::uint64_t> ticks{0};
  for (std::uint64_t k = last <= kAllLabelsUpTo ? 1 : last; k <= last && k > 0; ++k) ticks.push_back(k);
  for (std::size_t j = 0; j < ticks.size(); ++j) {
    out.push_back(text(frame_id, ns, id + static_cast<int>(j), axes.toX(ticks[j] + 0.5), axes.box.bottom - 0.28,
                       withSeparators(ticks[j]), kSmallTextSize));
  }
}
/// The paper's series of body i where it differs from the simulated one; true when some
/// of it lies off the panel's scale.
bool addPaperSeries(std::vector<Marker>& out, const RunRecord& run, const Axes& axes, int i, int id,
                    const std::string& frame_id) {
  const Envelope& paper = run.paperVelocity(i);
  if (paper.empty()) return false;
  const double tolerance = 1e-6 * (axes.y1 - axes.y0);
  addLines(out, markedSegments(frame_id, "plot", id, withTail(paper, static_cast<double>(run.collisions()) + 1),
                               axes, tolerance, kPaper));
  return !(axes.contains(paper.minY()) && axes.contains(paper.maxY()));
}

void addVelocityPlot(std::vector<Marker>& out, const RunRecord& run, const std::string& frame_id) {
  const auto panels = velocityPanels(run);
  const auto final_v = finalVelocitiesNotDrawn(run);
  const double tail = static_cast<double>(run.collisions()) + 1;
  bool paper_off_scale = false, paper_any = false;
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const Axes& axes = panels[p].axes;
    const int id = 100 * static_cast<int>(p);
    const std::string label = panels.size() == 1 ? "v [m/s]" : p == 0 ? "v_B [m/s]" : "v_A, v_C [m/s]";
    addFrame(out, frame_id, "plot", id, axes, label);
    for (int i : panels[p].bodies) {
      addSeries(out, frame_id, "plot", id + 10 + i, withTail(run.velocity(i), tail), axes, particleColor(i));
      Marker predicted = dots(frame_id, "plot", id + 20 + i, 0.09, particleColor(i, 0.6));
      for (const Keyframe* f : thinned(run.keyframes(), kMaxPredictedDots)) {
        predicted.points.push_back(point(axes.toX(f->index + 0.5), axes.toY(f->predicted[i]), 0.05));
      }
      if (final_v) predicted.points.push_back(point(axes.toX(final_v->first + 0.5), axes.toY(final_v->second[i]), 0.05));
      if (!predicted.points.empty()) out.push_back(predicted);
      paper_any = paper_any || !run.paperVelocity(i).empty();
      paper_off_scale = addPaperSeries(out, run, axes, i, id + 30 + i, frame_id) || paper_off_scale;
    }
  }
  addIndexAxisLabels(out, frame_id, "plot", 400, panels.back().axes);
  out.push_back(text(frame_id, "plot", 310, kVelocityBox.midX(), kPanelTitleY,
                     panels.size() > 1 ? "velocity vs collision index (B on its own scale)"
                                       : "velocity vs collision index",
                     kTextSize));
  std::string legend = "steps: simulated   dots: closed form";
  if (paper_any) legend += "   pink: paper's eqs. (2.15)/(2.16) where they differ";
  if (paper_off_scale) legend += " (clipped)";
  if (!paper_any && (isWall(run.input(), 0) || isWall(run.input(), 2))) legend += "   paper's (2.15)/(2.16): undefined with a wall";
  out.push_back(text(frame_id, "plot", 311, kVelocityBox.midX(), kLegendY, legend, kSmallTextSize, kLabelGrey));
  for (int i = 0; i < 3; ++i) {
    out.push_back(text(frame_id, "plot", 320 + i, kVelocityBox.right + 0.55, kVelocityBox.top - 0.4 * i,
                       std::string("v_") + kNames[i], kTextSize, particleColor(i)));
  }
}

// ---- energy and momentum against collision index ----

void addConservedPlot(std::vector<Marker>& out, const RunRecord& run, const Envelope& series, const Box& box,
                      int id, const std::string& label, const std::string& frame_id) {
  const auto [y0, y1] = paddedRange(series.minY(), series.maxY());
  const Axes axes{box, 0.0, indexAxisEnd(run), y0, y1};
  addFrame(out, frame_id, "conserved", id, axes, label);
  addSeries(out, frame_id, "conserved", id + 10, withTail(series, static_cast<double>(run.collisions()) + 1), axes,
            kWhite, 0.03);
  addIndexAxisLabels(out, frame_id, "conserved", id + 20, axes);
}

void addEnergyPlot(std::vector<Marker>& out, const RunRecord& run, const std::string& frame_id) {
  std::string energy = "E [J] of the finite masses vs collision index";
  std::string p = "p [kg m/s] of the finite masses vs collision index";
  if (run.summary && run.summary->simulated) {
    energy += format(";  drift %.2g", run.summary->energy_relative_drift);
    const double drift = run.summary->momentum_relative_drift;
    p += std::isnan(drift) ? "; a wall takes some" : format(";  drift %.2g", drift);
  }
  addConservedPlot(out, run, run.energy(), kEnergyBox, 0, energy, frame_id);
  addConservedPlot(out, run, run.momentum(), kMomentumBox, 100, p, frame_id);
}

// ---- worldlines ----

/// Time [s] up the box, position [m] across it (on the scene's axis).
struct WorldAxes {
  SceneAxis scene;
  double end = 1.0;
  double toX(double position) const {
    return kWorldBox.left + std::clamp((position - scene.min) / (scene.max - scene.min), 0.0, 1.0) *
                                (kWorldBox.right - kWorldBox.left);
  }
  double toY(double time) const {
    return kWorldBox.bottom + std::clamp(time / end, 0.0, 1.0) * (kWorldBox.top - kWorldBox.bottom);
  }
};

void addWorldlines(std::vector<Marker>& out, const RunRecord& run, const std::string& frame_id) {
  const WorldAxes axes{sceneAxis(run), endTime(run)};
  const SceneState last = stateAt(run, axes.end);
  Marker frame = lines(frame_id, "worldlines", 0, Marker::LINE_LIST, 0.025, kGrey);
  frame.points = {point(kWorldBox.left, kWorldBox.bottom), point(kWorldBox.right, kWorldBox.bottom),
                  point(kWorldBox.left, kWorldBox.bottom), point(kWorldBox.left, kWorldBox.top)};
  out.push_back(frame);
  for (int i = 0; i < 3; ++i) {
    Polyline poly = run.worldline(i).polyline();
    poly.push_back({last.time, last.positions[i], 0.0});
    Marker line = lines(frame_id, "worldlines", 10 + i, Marker::LINE_STRIP, isWall(run.input(), i) ? 0.08 : 0.03,
                        isWall(run.input(), i) ? kGrey : particleColor(i));
    for (const auto& v : poly) line.points.push_back(point(axes.toX(v.y), axes.toY(v.x)));
    addLines(out, line);
  }
  const auto label = [&](int id, double x, double y, const std::string& s) {
    out.push_back(text(frame_id, "worldlines", id, x, y, s, kSmallTextSize));
  };
  label(1, kWorldBox.left - 0.3, kWorldBox.bottom, "0");
  label(2, kWorldBox.left - 0.55, kWorldBox.top, format("%.3g", axes.end));
  label(3, kWorldBox.left - 0.45, kWorldBox.top + 0.3, "t [s]");
  label(4, kWorldBox.left, kWorldBox.bottom - 0.3, format("%.3g", axes.scene.min));
  label(5, kWorldBox.right, kWorldBox.bottom - 0.3, format("%.3g", axes.scene.max));
  label(6, kWorldBox.midX(), kWorldBox.bottom - 0.3, "x [m]");
  out.push_back(text(frame_id, "worldlines", 7, kWorldBox.midX(), kPanelTitleY, "x-t diagram (worldlines)", kTextSize));
  out.push_back(text(frame_id, "worldlines", 8, kWorldBox.midX(), kLegendY,
                     run.worldline(1).exact() ? "exact" : "min/max of x per time column", kSmallTextSize, kLabelGrey));
}

// ---- energy bars ----

void addBarsAxis(std::vector<Marker>& out, const RunRecord& run, const std::string& frame_id) {
  const double pitch = (kBarsBox.right - kBarsBox.left) / 3;
  Marker axis = lines(frame_id, "energy", 0, Marker::LINE_LIST, 0.03, kGrey);
  axis.points = {point(kBarsBox.left, kBarsBox.bottom), point(kBarsBox.right, kBarsBox.bottom)};
  out.push_back(axis);
  for (int i = 0; i < 3; ++i) {
    out.push_back(text(frame_id, "energy", 1 + i, kBarsBox.left + (i + 0.5) * pitch, kBarsBox.bottom - 0.3,
                       isWall(run.input(), i) ? std::string(kNames[i]) + " (wall)" : kNames[i], kSmallTextSize,
                       particleColor(i)));
  }
  out.push_back(text(frame_id, "energy", 4, kBarsBox.midX(), kBarsBox.top + 0.75,
                     "kinetic energy now [J]", kTextSize));
}

}  // namespace

MarkerArray buildStaticMarkers(const RunRecord& run, const std::string& frame_id) {
  MarkerArray array;
  auto& out = array.markers;
  out.push_back(text(frame_id, "title", 0, kCentreX, kTitleY, runTitle(run), kTitleSize));
  addSceneAxis(out, run, frame_id);
  addWedge(out, run, frame_id);
  addVelocityPlot(out, run, frame_id);
  addEnergyPlot(out, run, frame_id);
  addWorldlines(out, run, frame_id);
  addBarsAxis(out, run, frame_id);
  return array;
}

namespace {

void addBodies(std::vector<Marker>& out, const RunRecord& run, const SceneState& state, const std::string& frame_id) {
  const SceneAxis axis = sceneAxis(run);
  for (int i = 0; i < 3; ++i) {
    const bool wall = isWall(run.input(), i);
    const double x = axis.toX(state.positions[i]);
    if (wall) {
      Marker m = base(frame_id, "bodies", i, Marker::CUBE);
      m.pose.position = point(x + (i == 0 ? 0.1 : -0.1), kSceneY);
      m.scale.x = 0.2, m.scale.y = 1.8, m.scale.z = 0.3;
      m.color = kGrey;
      out.push_back(m);
    } else {
      Marker m = base(frame_id, "bodies", i, Marker::SPHERE);
      m.pose.position = point(x, kSceneY);
      m.scale.x = m.scale.y = m.scale.z = bodyDiameter(run.input(), i);
      m.color = particleColor(i);
      out.push_back(m);
    }
    // A short tag beside the body (walls: on their outer side), the value in a fixed row.
    const double tag_x = wall ? x + (i == 0 ? 0.8 : -0.8) : x;
    const double tag_y = wall ? kSceneY + 0.5 : kSceneY + (i == 1 ? -0.5 : 0.5);
    out.push_back(text(frame_id, "labels", i, tag_x, tag_y, wall ? std::string(kNames[i]) + " (wall)" : kNames[i],
                       kTextSize, particleColor(i, 0.3)));
    out.push_back(text(frame_id, "labels", 10 + i, kCentreX + 6.8 * (i - 1), kVelocityRowY,
                       std::string("v_") + kNames[i] + format(" = %.6g m/s", state.velocities[i]), kTextSize,
                       particleColor(i, 0.3)));
  }
}

/// A magnifier under the scene while the bodies crowd together (less than 5 % of the axis
/// apart): the three at their true separations, in a window a power of ten wide.
void addZoom(std::vector<Marker>& out, const RunRecord& run, const SceneState& state, const std::string& frame_id) {
  constexpr int kMarkers = 6;  // ids 0..5 of ns "zoom"
  const SceneAxis axis = sceneAxis(run);
  const auto [lo, hi] = std::minmax({state.positions[0], state.positions[1], state.positions[2]});
  const double full = axis.max - axis.min;
  if (!(hi - lo > 0) || hi - lo > 0.05 * full) {
    for (int id = 0; id < kMarkers; ++id) out.push_back(deleteMarker("zoom", id, frame_id));
    return;
  }
  const double window = std::pow(10.0, std::ceil(std::log10(1.6 * (hi - lo))));
  const double left = kSceneLeft + 5.0, right = kSceneRight - 5.0, middle = (lo + hi) / 2;
  const auto toX = [&](double x) { return left + ((x - middle) / window + 0.5) * (right - left); };
  Marker line = lines(frame_id, "zoom", 0, Marker::LINE_LIST, 0.02, kGrey);
  line.points = {point(left, kZoomY), point(right, kZoomY)};
  out.push_back(line);
  for (int i = 0; i < 3; ++i) {
    Marker body = base(frame_id, "zoom", 1 + i, isWall(run.input(), i) ? Marker::CUBE : Marker::SPHERE);
    // B, the light one, on top: at a collision it touches A or C.
    body.pose.position = point(toX(state.positions[i]), kZoomY, i == 1 ? 0.3 : 0.05);
    body.scale.x = isWall(run.input(), i) ? 0.08 : (i == 1 ? 0.16 : 0.26);
    body.scale.y = isWall(run.input(), i) ? 0.6 : body.scale.x;
    body.scale.z = body.scale.x;
    body.color = isWall(run.input(), i) ? kGrey : particleColor(i);
    out.push_back(body);
  }
  out.push_back(text(frame_id, "zoom", 4, left - 2.2, kZoomY, format("magnified x%.2g", full / window),
                     kSmallTextSize, kLabelGrey));
  out.push_back(text(frame_id, "zoom", 5, right + 2.5, kZoomY,
                     format("window %.2g m", window) + format(" from %.3g m", middle - window / 2), kSmallTextSize,
                     kLabelGrey));
}

std::string statusLine(const RunRecord& run, const SceneState& state, const FrameClock& clock) {
  std::string s = format("t = %.6g s", state.time) + "     collisions " + withSeparators(state.collisions);
  const std::uint64_t expected = expectedCollisions(run);
  if (run.finished()) {
    s += " of " + withSeparators(run.collisions());
  } else if (expected > state.collisions) {
    s += " (" + withSeparators(expected) + " predicted)";
  }
  if (!clock.description.empty()) s += "     " + clock.description;
  return s;
}

void addCursors(std::vector<Marker>& out, const RunRecord& run, const SceneState& state, const std::string& frame_id) {
  const WedgeFrame wedge(run.input());
  Marker now = base(frame_id, "wedge_now", 0, Marker::SPHERE);
  now.pose.position = wedgePoint(wedge.project(state.velocities), wedgeScale(wedge, run), 0.1);
  now.scale.x = now.scale.y = now.scale.z = 0.3;
  out.push_back(now);

  // The current step [k, k+1] of the index plots.
  const Axes index{kVelocityBox, 0.0, indexAxisEnd(run), 0.0, 1.0};
  const double cx = index.toX(static_cast<double>(state.collisions) + 0.5);
  Marker cursor = lines(frame_id, "plot_cursor", 0, Marker::LINE_LIST, 0.02, color(1, 1, 1, 0.5));
  cursor.points = {point(cx, kVelocityBox.bottom), point(cx, kVelocityBox.top), point(cx, kMomentumBox.bottom),
                   point(cx, kEnergyBox.top)};
  out.push_back(cursor);

  const WorldAxes world{sceneAxis(run), endTime(run)};
  Marker now_line = lines(frame_id, "worldlines_now", 0, Marker::LINE_LIST, 0.02, color(1, 1, 1, 0.5));
  now_line.points = {point(kWorldBox.left, world.toY(state.time)), point(kWorldBox.right, world.toY(state.time))};
  out.push_back(now_line);
  Marker bodies = dots(frame_id, "worldlines_now", 1, 0.16, kWhite);
  for (double x : state.positions) bodies.points.push_back(point(world.toX(x), world.toY(state.time), 0.05));
  out.push_back(bodies);
}

void addBars(std::vector<Marker>& out, const RunRecord& run, const SceneState& state, const std::string& frame_id) {
  std::array<double, 3> kinetic{};
  for (int i = 0; i < 3; ++i) {
    if (!isWall(run.input(), i)) kinetic[i] = 0.5 * run.input().masses[i] * state.velocities[i] * state.velocities[i];
  }
  const double total = kinetic[0] + kinetic[1] + kinetic[2];
  const double pitch = (kBarsBox.right - kBarsBox.left) / 3;
  const double height = kBarsBox.top - kBarsBox.bottom;
  for (int i = 0; i < 3; ++i) {
    const double h = std::max(total > 0 ? height * kinetic[i] / total : 0.0, 0.01);
    const double x = kBarsBox.left + (i + 0.5) * pitch;
    Marker bar = base(frame_id, "energy_bars", i, Marker::CUBE);
    bar.pose.position = point(x, kBarsBox.bottom + h / 2);
    bar.scale.x = 0.6 * pitch, bar.scale.y = h, bar.scale.z = 0.1;
    bar.color = particleColor(i);
    out.push_back(bar);
    out.push_back(text(frame_id, "energy_bars", 10 + i, x, kBarsBox.bottom + h + 0.25, format("%.3g", kinetic[i]),
                       kSmallTextSize));
  }
}

}  // namespace

MarkerArray buildAnimatedMarkers(const RunRecord& run, const FrameClock& clock, const std::string& frame_id) {
  MarkerArray array;
  auto& out = array.markers;
  const SceneState state = stateAt(run, clock.t);
  addBodies(out, run, state, frame_id);
  addZoom(out, run, state, frame_id);
  out.push_back(text(frame_id, "labels", 3, kCentreX, kStatusY, statusLine(run, state, clock), kTextSize));
  addCursors(out, run, state, frame_id);
  addBars(out, run, state, frame_id);
  return array;
}

namespace {

/// A text with a frame around it. The frame also makes rviz 1.14 draw a text that comes
/// alone: an array of only TEXT_VIEW_FACING markers is received but not drawn.
std::vector<Marker> framedText(const std::string& frame_id, const std::string& ns, double y, const std::string& s,
                               const std_msgs::ColorRGBA& c, double size) {
  std::size_t longest = 0, lines_count = 1, start = 0;
  for (std::size_t end = s.find('\n'); ; end = s.find('\n', start)) {
    longest = std::max(longest, (end == std::string::npos ? s.size() : end) - start);
    if (end == std::string::npos) break;
    start = end + 1;
    ++lines_count;
  }
  // rviz's font is about 0.42 text heights wide per character, 1.25 high per line.
  const double half_width = std::min(0.21 * size * static_cast<double>(longest) + 0.4, 13.0);
  const double half_height = 0.62 * size * static_cast<double>(lines_count) + 0.2;
  Marker box = lines(frame_id, ns, 1, Marker::LINE_LIST, 0.03, c);
  const double l = kCentreX - half_width, r = kCentreX + half_width;
  const double b = y - half_height, t = y + half_height;
  box.points = {point(l, b), point(r, b), point(r, b), point(r, t), point(r, t), point(l, t), point(l, t), point(l, b)};
  return {text(frame_id, ns, 0, kCentreX, y, s, size, c), box};
}

}  // namespace

std::vector<Marker> rejectedBanner(const collision_lab::Rejected& rejected, const std::string& frame_id) {
  const std::string run = rejected.run_id.empty() ? "an input" : "run '" + rejected.run_id + "'";
  return framedText(frame_id, "rejected", kZoomY,
                    "REJECTED " + run + ": " + rejected.reason_name + " in " + rejected.field + "\n" +
                        rejected.message,
                    color(1.0, 0.35, 0.35), kTextSize);
}

std::vector<Marker> hintMarkers(const std::string& command, const std::string& frame_id) {
  // Large: an underscore one pixel thin would vanish, and this is a command to copy.
  return framedText(frame_id, "hint", 1.5, command, kWhite, 0.44);
}

Marker deleteMarker(const std::string& ns, int id, const std::string& frame_id) {
  Marker m;
  m.header.frame_id = frame_id;
  m.ns = ns;
  m.id = id;
  m.action = Marker::DELETE;
  return m;
}

MarkerArray deleteAllMarkers(const std::string& frame_id) {
  MarkerArray array;
  Marker m;
  m.header.frame_id = frame_id;
  m.action = Marker::DELETEALL;
  array.markers.push_back(m);
  return array;
}

namespace {

bool finitePoint(const geometry_msgs::Point& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

/// Keeps every k-th point (k-th pair for a LINE_LIST) so that at most `limit` remain.
void thin(Marker& m, std::size_t limit) {
  const std::size_t group = m.type == Marker::LINE_LIST ? 2 : 1;
  const std::size_t groups = m.points.size() / group;
  const std::size_t stride = (groups + limit / group - 1) / (limit / group);
  std::vector<geometry_msgs::Point> kept;
  for (std::size_t g = 0; g < groups; g += stride) {
    kept.insert(kept.end(), m.points.begin() + g * group, m.points.begin() + (g + 1) * group);
  }
  m.points.swap(kept);
  m.colors.clear();
}

/// False when rviz would reject the marker; fixes what it can (see enforceRvizLimits).
bool fitForRviz(Marker& m, bool& changed) {
  if (m.action != Marker::ADD) return true;
  const auto finite = [](double v) { return std::isfinite(v); };
  if (!finite(m.pose.position.x) || !finite(m.pose.position.y) || !finite(m.pose.position.z)) return false;
  switch (m.type) {
    case Marker::TEXT_VIEW_FACING:
      return m.text.find_first_not_of(" \t\n") != std::string::npos;
    case Marker::LINE_STRIP:
    case Marker::LINE_LIST:
    case Marker::SPHERE_LIST:
    case Marker::CUBE_LIST:
    case Marker::POINTS:
    case Marker::TRIANGLE_LIST: break;
    default: return true;
  }
  if (!std::all_of(m.points.begin(), m.points.end(), finitePoint)) {
    std::vector<geometry_msgs::Point> kept;
    std::copy_if(m.points.begin(), m.points.end(), std::back_inserter(kept), finitePoint);
    if (m.type == Marker::LINE_LIST || m.type == Marker::TRIANGLE_LIST) return false;  // pairing lost
    m.points.swap(kept);
    m.colors.clear();
    changed = true;
  }
  if (m.type == Marker::TRIANGLE_LIST) return !m.points.empty() && m.points.size() % 3 == 0;
  if (m.type == Marker::LINE_LIST && m.points.size() % 2 != 0) return false;
  if ((m.type == Marker::LINE_STRIP || m.type == Marker::LINE_LIST) && m.points.size() > kRvizMaxLinePoints) {
    thin(m, kRvizMaxLinePoints);
    changed = true;
  }
  return m.points.size() >= (m.type == Marker::LINE_STRIP || m.type == Marker::LINE_LIST ? 2u : 1u);
}

}  // namespace

std::size_t enforceRvizLimits(MarkerArray& array) {
  std::size_t changed_count = 0;
  std::vector<Marker> kept;
  kept.reserve(array.markers.size());
  for (Marker& m : array.markers) {
    bool changed = false;
    if (fitForRviz(m, changed)) {
      kept.push_back(std::move(m));
    } else {
      changed = true;
    }
    changed_count += changed ? 1 : 0;
  }
  array.markers.swap(kept);
  return changed_count;
}

}  // namespace collision_lab_ros
