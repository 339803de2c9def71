// A run as its messages describe it, kept for drawing in bounded memory whatever the
// count (a RunRecord: a decimated set of exact states, Keyframes, and per-pixel-column
// min/max envelopes of every plotted series, Envelope), and the run's state at a time. The
// view model (run_view.h) and the rviz markers (marker_builder.h) both read it; it draws
// nothing itself.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <ros/time.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/core/nbody/body_state_replay.h"
#include "collision_lab/core/nbody/temperature.h"
#include "collision_lab/ros/node_constants.h"

namespace collision_lab_ros {

/// A polyline y(x), appended to with x never decreasing, in bounded memory. While it has
/// at most max_vertices vertices it is kept exactly; beyond, it is kept per column of
/// x (a power of two wide, at most max_vertices / 4 columns): the first and last vertex
/// and the min and max of y over the column, which is all a pixel column can show. Each
/// vertex carries a mark (e.g. a deviation); a column keeps the largest.
class Envelope {
 public:
  struct Vertex {
    double x = 0.0, y = 0.0, mark = 0.0;
  };

  explicit Envelope(std::size_t max_vertices = kMarkerEnvelopeVertices);

  /// Appends a vertex; x >= 0 and x >= the previous x. NaN y is kept (a gap) and ignored
  /// by the bounds.
  void add(double x, double y, double mark = 0.0);
  /// Appends a step: holds the last y up to x, then jumps to y (no jump when y and mark
  /// are unchanged; the first call just adds).
  void step(double x, double y, double mark = 0.0);

  /// The polyline to draw: the exact vertices, or per column first, min/max, last. At
  /// most max_vertices points.
  std::vector<Vertex> polyline() const;
  bool empty() const { return count_ == 0; }
  bool exact() const { return columns_.empty(); }
  const Vertex& last() const { return last_; }
  /// Bounds of y over every vertex ever added (+inf / -inf when none is finite).
  double minY() const { return min_y_; }
  double maxY() const { return max_y_; }
  /// Heap bytes held (vertices and columns, by capacity) [bytes].
  std::size_t memoryBytes() const;

 private:
  struct Column {
    bool used = false;
    Vertex first, last;
    double lo = 0.0, hi = 0.0, mark = 0.0;
  };
  void addToColumns(const Vertex& v);
  void addToColumn(std::size_t c, const Vertex& v);
  void switchToColumns(double x);
  void widenColumns();

  std::size_t max_vertices_;
  std::size_t count_ = 0;
  std::vector<Vertex> vertices_;  ///< exact mode
  std::vector<Column> columns_;   ///< column mode (empty in exact mode)
  double width_ = 0.0;            ///< column width [x units], a power of two
  Vertex last_;
  double min_y_, max_y_;
};

/// The exact state of every body just after one collision (or a collapse).
struct Keyframe {
  std::uint64_t index = 0;  ///< collisions so far [1] (a collapse keeps its impacts' count)
  double time = 0.0;        ///< [s]
  /// Up to this time [s] the free flight from this state is exact: the next collision's
  /// time once it is known, +inf while this is the newest collision.
  double valid_until = 0.0;
  double previous_time = 0.0;      ///< the previous collision's time [s] (0 for the first)
  std::vector<double> positions;   ///< body i at index i [m]
  std::vector<double> velocities;  ///< after the collision [m/s]
  std::vector<double> predicted;   ///< closed form after the collision [m/s]; empty when none
  bool collapse = false;           ///< the state after a collapse (KIND_COLLAPSE), not an impact
};

/// Bounds of a RunRecord's memory, whatever the count and N.
struct RecordLimits {
  std::size_t keyframes = kMarkerKeyframes;
  std::size_t envelope_vertices = kMarkerEnvelopeVertices;
  /// Keyframes hold N values each: at most this many values in all, so a 1,000-body gas
  /// keeps about a thousand states [1].
  std::size_t keyframe_values = std::size_t{1} << 21;
  /// False: no keyframes are kept (keyframes() then has the newest state only). For a
  /// reader that never animates the scene, such as the web node, whose plots need only the
  /// envelopes; a 1,000-body gas then costs kilobytes instead of megabytes.
  bool keep_keyframes = true;
};

/// Bodies whose worldlines the x-t diagram draws (all of them up to this N; beyond, this
/// many evenly spaced ones, the outermost two included), and bodies with their own
/// velocity and energy steps (all up to kMaxPlottedBodies; beyond, none: the plots show sums).
constexpr std::size_t kMaxTrackedBodies = 24;
constexpr std::size_t kMaxPlottedBodies = 10;

/// What the marker view keeps of one run of N bodies. Collisions are added in index order;
/// the record keeps the first and the newest collision, every collision whose index is a
/// multiple of a power-of-two stride, and the first collision in every time bucket (a
/// power of two wide), doubling stride or bucket as needed to stay within the limits. So
/// both the sparse phases (uniform in time) and the dense bursts (uniform in index) keep
/// exact states close together.
/// The state of every body is the core's replay (core::BodyStateReplay) of the
/// InitialConditions and each event's pair fields: O(1) per impact (O(size) for a cluster), so a 1,000-body gas with 245,000 impacts costs 245,000 small updates; a
/// keyframe (O(N)) is copied only when it is kept.
/// Not thread-safe, not even for const calls (keyframes() materialises the newest state).
class RunRecord {
 public:
  explicit RunRecord(const collision_lab::InitialConditions& input, const RecordLimits& limits = {});

  /// Collisions must come in index order; an index already added is ignored, and a
  /// skipped index is counted in missedCollisions(). A KIND_COLLAPSE record (its index is
  /// the count of the impacts before it) is applied once. An event naming bodies the scene
  /// does not have is counted in malformedEvents() and ignored.
  void add(const collision_lab::CollisionEvent& event);
  /// A sampled state past a gap (a RunProgress's latest_event, the web node's live view past
  /// ~max_published_events): the counter and clock move to it, the replay goes on from its
  /// state (positions and velocities_after of every body, heat so far [J]) and every series
  /// gets one point, drawn straight from the state before; the collisions between are known
  /// by count only (sampledCollisions()), not missed. An index not past the newest is
  /// ignored; a sample without the state of every body, or naming bodies the scene does not
  /// have, is counted in malformedEvents() and ignored.
  void addSample(const collision_lab::CollisionEvent& event, double heat);

  const collision_lab::InitialConditions& input() const { return input_; }
  std::optional<collision_lab::Prediction> prediction;
  std::optional<collision_lab::RunSummary> summary;

  /// Number of bodies N (walls included) [1].
  std::size_t bodies() const { return input_.masses.size(); }
  bool isWall(std::size_t i) const;
  /// Index of the newest collision added [1].
  std::uint64_t collisions() const { return newest_index_; }
  std::uint64_t missedCollisions() const { return missed_; }
  std::uint64_t malformedEvents() const { return malformed_; }
  /// True once a sample was added: the series are decimated past sampledAfter(), the
  /// newest collision received one by one [1]; sampledCollisions() lie between samples [1].
  bool sampled() const { return sampled_; }
  std::uint64_t sampledAfter() const { return sampled_after_; }
  std::uint64_t sampledCollisions() const { return sampled_collisions_; }
  /// One collapse: its time [s], point [m] and bodies, first .. last [1].
  struct CollapseMark {
    double time = 0.0;
    double position = 0.0;
    std::pair<std::size_t, std::size_t> bodies{0, 0};
  };
  /// The first kNamedCollapses collapses are kept, in order; collapses() counts them all.
  static constexpr std::size_t kNamedCollapses = 3;
  /// Collapses applied [1].
  std::uint32_t collapses() const { return collapses_; }
  const std::vector<CollapseMark>& namedCollapses() const { return named_collapses_; }
  /// Time of the newest collision added [s] (0 before the first).
  double newestTime() const { return newest_time_; }
  /// Bounds of every finite velocity any body has had so far, the start's included [m/s]:
  /// every state the record can show lies within them.
  double minVelocity() const { return min_velocity_; }
  double maxVelocity() const { return max_velocity_; }
  /// The kept states, the newest last (materialised on demand).
  const std::vector<Keyframe>& keyframes() const;
  /// True when every collision of the run is here: the summary (or, before it, the exact
  /// predicted count) says the simulated run ended with the newest collision.
  bool finished() const;

  /// Bodies with a worldline (kMaxTrackedBodies) and with velocity and energy steps
  /// (kMaxPlottedBodies), in increasing order.
  const std::vector<std::size_t>& trackedBodies() const { return tracked_; }
  const std::vector<std::size_t>& plottedBodies() const { return plotted_; }

  /// Steps against collision index, per plotted body i: velocity [m/s] (simulated, and
  /// the paper's with mark |paper - simulated|) and kinetic energy [J]; total kinetic
  /// energy [J] and momentum [kg m/s] of the finite masses, and the energy turned into heat
  /// so far [J]. Worldlines, per tracked body i: position [m] against time [s].
  /// Precondition: i is plotted (tracked for worldline); otherwise an empty envelope.
  const Envelope& velocity(std::size_t i) const { return seriesOf(velocity_, plot_slot_, i); }
  const Envelope& paperVelocity(std::size_t i) const { return seriesOf(paper_velocity_, plot_slot_, i); }
  const Envelope& bodyEnergy(std::size_t i) const { return seriesOf(body_energy_, plot_slot_, i); }
  const Envelope& worldline(std::size_t i) const { return seriesOf(worldline_, track_slot_, i); }
  /// Large scenes (no plotted bodies): velocity steps [m/s] of each tracked body i.
  const Envelope& trackedVelocity(std::size_t i) const { return seriesOf(tracked_velocity_, track_slot_, i); }
  const Envelope& energy() const { return energy_; }
  const Envelope& momentum() const { return momentum_; }
  const Envelope& energyLost() const { return energy_lost_; }
  /// Granular temperature T = (1/N) sum m (v - V)^2 of the finite masses [J] against time
  /// [s] (core::granularTemperature, from the running energy and momentum) after each
  /// collision: the gas's T(t), thinned evenly in log t (core::LogTimeSamples: the start,
  /// 50 per decade of time and the newest), so that a log-log plot sees the early cooling of
  /// a run that lasts 1e7 s.
  std::vector<collision_lab::core::TemperatureSample> temperature() const { return temperature_.samples(); }
  /// The same T sampled as the CLI's --temperature-csv samples it (the start, every
  /// core::temperatureStride(N)-th impact, each collapse and the newest), thinned alike:
  /// Haff's fit to these is the CLI's.
  std::vector<collision_lab::core::TemperatureSample> temperatureForFit() const;
  /// Total kinetic energy of the finite masses at the start [J].
  double startEnergy() const { return start_energy_; }
  /// Bytes the record holds, itself included: its input, the replay's state, the kept
  /// keyframes and every envelope, vectors counted by capacity [bytes].
  std::size_t memoryBytes() const;

 private:
  /// Empty when i has no slot or `series` is not kept.
  const Envelope& seriesOf(const std::vector<Envelope>& series, const std::vector<int>& slot, std::size_t i) const;
  bool wellFormed(const collision_lab::CollisionEvent& event) const;
  /// Applies the event to the replay and the series.
  void apply(const collision_lab::CollisionEvent& event);
  /// Makes event the newest collision (its index, time, kind and collapse): the kept state
  /// before it is exact up to its time only when `follows` (no collision between).
  void makeNewest(const collision_lab::CollisionEvent& event, bool follows);
  /// One step of every per-collision series at the newest collision, from the replay.
  void stepSeries(const collision_lab::CollisionEvent& event);
  /// Keeps the newest state as a keyframe when the stride and buckets say so.
  void keepNewest(const collision_lab::CollisionEvent& event);
  /// Adds the moved body's new state (from the replay) to its worldline and velocity range.
  void recordMove(std::size_t body, double time);
  void widenVelocityRange(double v);
  Keyframe snapshot(double time) const;
  bool keeps(const Keyframe& frame) const;
  void prune();
  std::size_t keyframeLimit() const;

  collision_lab::InitialConditions input_;
  RecordLimits limits_;
  collision_lab::core::BodyStateReplay replay_;  ///< every body now, from the events' pair fields
  mutable std::vector<Keyframe> keyframes_;
  /// keyframes_.back() is the newest state materialised for keyframes(), not a kept one.
  mutable bool provisional_ = false;
  std::uint64_t newest_index_ = 0;
  double newest_time_ = 0.0, previous_time_ = 0.0;
  bool has_newest_ = false, newest_kept_ = false, newest_is_collapse_ = false;
  std::vector<double> newest_predicted_;
  std::uint64_t stride_ = 1;   ///< keeps indices that are multiples of it
  double bucket_ = 0.0;        ///< [s]; 0 until the first collision at t > 0
  std::uint64_t missed_ = 0, malformed_ = 0;
  bool sampled_ = false;
  std::uint64_t sampled_after_ = 0, sampled_collisions_ = 0;
  std::uint32_t collapses_ = 0;
  std::vector<CollapseMark> named_collapses_;
  std::vector<std::size_t> tracked_, plotted_;
  std::vector<int> track_slot_, plot_slot_;  ///< body -> its series, -1 for none
  std::vector<Envelope> velocity_, paper_velocity_, body_energy_, worldline_;
  std::vector<Envelope> tracked_velocity_;  ///< empty unless no body is plotted
  Envelope energy_, momentum_, energy_lost_, none_;
  collision_lab::core::LogTimeSamples temperature_, temperature_fit_;
  std::optional<collision_lab::core::TemperatureSample> temperature_newest_;  ///< not offered to temperature_ yet
  std::uint64_t temperature_stride_ = 1;
  std::uint64_t temperature_fit_bucket_ = 0;  ///< index / stride of the last impact offered to temperature_fit_
  double finite_mass_ = 0.0;         ///< [kg]
  std::size_t finite_bodies_ = 0;    ///< [1]
  double temperatureNow() const;
  double start_energy_ = 0.0;
  double min_velocity_, max_velocity_;
};

/// How long bodies at positions x [m] with velocities v [m/s] fly freely before two
/// touch [s]: +inf when no pair approaches. Bounds the animation of an unfinished run.
double freeFlightHorizon(const std::vector<double>& x, const std::vector<double>& v);

/// What the scene shows at simulated time t [s].
struct SceneState {
  /// The simulated time shown [s]: t itself when its exact state is known, otherwise the
  /// nearest instant whose exact state is known (never an extrapolation).
  double time = 0.0;
  std::vector<double> positions;   ///< body i at index i [m]
  std::vector<double> velocities;  ///< [m/s]
  std::uint64_t collisions = 0;    ///< collisions before `time` [1]
};
SceneState stateAt(const RunRecord& run, double t);

/// The simulated time [s] the animation runs to: 25 % past the last collision of a
/// finished run, or past the bodies' closest approach when nothing collides; for an
/// unfinished run, as far as its known trajectory goes.
double endTime(const RunRecord& run);

/// The animation's time warp: phase in [0, 1] (one loop) -> simulated time [s], a blend of
/// uniform time and uniform collision index, so dense bursts play in slow motion.
class TimeWarp {
 public:
  explicit TimeWarp(const RunRecord& run);
  double timeAt(double phase) const;
  /// d(simulated time)/d(phase) at phase [s per loop].
  double rateAt(double phase) const;

 private:
  std::vector<double> times_, phases_;  ///< increasing nodes of the piecewise-linear map
  double end_ = 0.0;
};

/// Wall seconds of one auto-timed loop of a run with this many collisions.
double autoLoopDuration(std::uint64_t collisions);

/// Simulated time [s] of a replayed run at ROS time `now`, on the run's timeline stamped
/// from `start` (its InitialConditions) at timeline_scale bag s per simulated s; a scale
/// <= 0 or not finite counts as 1. Never negative.
double simulatedTimeOnTimeline(const ros::Time& now, const ros::Time& start, double timeline_scale);

/// Simulated time [s] of a run replayed by `rosbag play --clock` at ROS time `now`: on the
/// run's timeline (its InitialConditions stamp, Prediction.timeline_scale), but never before
/// the newest collision received. rosbag play sends a message once its clock has reached
/// the message's stamp, yet the /clock it publishes (at most every 10 ms of wall time) lags
/// that stamp and stops with the last message, and a stamp rounded to the nanosecond can
/// fall just before its collision's time: the received collision has happened.
double replayedTime(const RunRecord& run, const ros::Time& now);

}  // namespace collision_lab_ros
