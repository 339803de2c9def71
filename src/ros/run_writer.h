// The messages of one run, as the lab node's workers send them (internal to src/ros):
// RunWriter stamps, publishes and records; EventStream turns the core's impacts into
// CollisionEvents, their plot projections and the run's progress.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <new>
#include <optional>
#include <string>
#include <utility>

#include <ros/serialization.h>

#include "collision_lab/ros/lab_node.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_recorder.h"
#include "collision_lab/ros/run_timeline.h"
#include "collision_lab/service/admission.h"
#include "collision_lab/service/student_quota.h"

namespace collision_lab_ros {

/// Stamps the messages of one run on its timeline, publishes them and hands what is
/// recorded over to the bag writer, in batches of at most kRecordBatchEvents events.
/// Counts the serialized bytes it records: past max_bag_bytes (0: no limit), or when the
/// bag directory's free space is under its floor (looked at every kFreeSpaceProbeBytes), it
/// calls on_limit once (the run is then stopped; what the run still computes is recorded).
class RunWriter {
 public:
  enum class Limit { kBagBytes, kFreeSpace, kStudentQuota };
  /// What recording may take: bytes per bag (0: no limit) and the free space it leaves.
  struct RecordLimits {
    std::uint64_t max_bag_bytes = 0;
    const collision_lab::service::Admission* admission = nullptr;  ///< the free-space floor; null: none
    collision_lab::service::StudentQuota* quota = nullptr;  ///< null: none
    std::string student;             ///< whose quota the run's bytes count in
  };
  /// bags may be null (not recording). claim_error: RunBagBatch::claim_error.
  RunWriter(std::string run_id, RunTimeline timeline, RunBagWriter* bags, std::string claim_error,
            RecordLimits limits, std::function<void(Limit)> on_limit)
      : run_id_(std::move(run_id)), timeline_(timeline), bags_(bags), limits_(std::move(limits)),
        on_limit_(std::move(on_limit)) {
    batch_.run_id = run_id_;
    batch_.opens = true;
    batch_.claim_error = std::move(claim_error);
  }

  RunWriter(const RunWriter&) = delete;
  RunWriter& operator=(const RunWriter&) = delete;
  /// A run that never handed its summary over (its end failed) gives its counted bytes back
  /// to its student's quota; a finished one does so when its bag is closed (publishEnd).
  ~RunWriter() {
    if (!handed_over_ && limits_.quota) limits_.quota->ended(limits_.student, quota_bytes_, 0);
  }

  const RunTimeline& timeline() const { return timeline_; }
  bool recording() const { return bags_ != nullptr; }
  /// True once the run's summary was handed over (finish()) or, not recording, is being
  /// published (markFinished()).
  bool finished() const { return finished_; }
  void markFinished() { finished_ = true; }
  /// [bytes] serialized size of the messages recorded so far.
  std::uint64_t recordedBytes() const { return recorded_bytes_; }
  /// [bytes] of them counted in the student's quota (RecordLimits::quota).
  std::uint64_t quotaBytes() const { return quota_bytes_; }
  /// [s] of this (the node's) thread spent handing messages over to the bag writer.
  double recordingSeconds() const { return recording_time_.count(); }

  /// Sets run_id and header.stamp: the timeline's stamp of simulated time t [s].
  template <class Message>
  void stamp(Message& msg, double t) {
    msg.run_id = run_id_;
    msg.header.stamp = timeline_.stamp(t);
  }
  /// Stamps at t and publishes.
  template <class Message>
  void publish(const ros::Publisher& pub, Message& msg, double t) {
    stamp(msg, t);
    pub.publish(msg);
  }

  /// Records the run's parameters, stamped at the run's start.
  void record(collision_lab::RunParameters parameters) {
    if (!bags_) return;
    stamp(parameters, 0.0);
    count(parameters);
    timed([&] { batch_.parameters = std::move(parameters); });
  }
  /// Record (at their header.stamp): the input, the prediction, each event.
  void record(const collision_lab::InitialConditions& input) {
    if (!bags_) return;
    count(input);
    timed([&] { batch_.input = input; });
  }
  void record(const collision_lab::Prediction& prediction) {
    if (!bags_) return;
    count(prediction);
    timed([&] { batch_.prediction = prediction; });
  }
  void record(collision_lab::CollisionEvent&& event) {
    if (!bags_) return;
    count(event);
    timed([&] {
      batch_.events.push_back(std::move(event));
      if (batch_.events.size() >= kRecordBatchEvents) handOver();
    });
  }
  /// Records the summary last and closes the bag on the writer's thread, which then
  /// calls on_closed with the summary's final recording fields.
  void finish(const collision_lab::RunSummary& summary,
              std::function<void(collision_lab::RunSummary&)> on_closed) {
    finished_ = true;
    timed([&] {
      batch_.summary = summary;
      batch_.on_closed = std::move(on_closed);
      handOver();
    });
    handed_over_ = true;
  }

 private:
  template <class Message>
  void count(const Message& msg) {
    const std::uint32_t bytes = ros::serialization::serializationLength(msg);
    recorded_bytes_ += bytes;
    batch_.bytes += bytes;
    if (over_limit_) return;
    if (limits_.max_bag_bytes > 0 && recorded_bytes_ > limits_.max_bag_bytes) return reach(Limit::kBagBytes);
    if (recorded_bytes_ < next_probe_) return;
    next_probe_ = recorded_bytes_ + kFreeSpaceProbeBytes;
    const bool over_quota = limits_.quota && limits_.quota->recorded(limits_.student, recorded_bytes_ - quota_bytes_);
    quota_bytes_ = recorded_bytes_;
    if (over_quota) return reach(Limit::kStudentQuota);
    // What the bag writers still hold will take space too.
    if (limits_.admission && limits_.admission->underFloor(RunBagWriter::bytesWaiting())) reach(Limit::kFreeSpace);
  }
  void reach(Limit limit) {
    over_limit_ = true;
    if (on_limit_) on_limit_(limit);
  }
  template <class F>
  void timed(F&& f) {
    const auto start = std::chrono::steady_clock::now();
    f();
    recording_time_ += std::chrono::steady_clock::now() - start;
  }
  void handOver() {
    bags_->push(std::move(batch_));
    batch_ = RunBagBatch();
    batch_.run_id = run_id_;
  }

  std::string run_id_;
  RunTimeline timeline_;
  RunBagWriter* bags_;
  RunBagBatch batch_;
  std::chrono::duration<double> recording_time_{0.0};
  RecordLimits limits_;
  std::function<void(Limit)> on_limit_;
  std::uint64_t recorded_bytes_ = 0;
  std::uint64_t next_probe_ = 0;  ///< the first message looks: a run may start under the floor or over its quota
  std::uint64_t quota_bytes_ = 0;
  bool handed_over_ = false;  ///< finish() handed the summary, and the quota's bytes, to the bag writer
  bool over_limit_ = false;
  bool finished_ = false;
};

/// What of a run's collisions goes out on the topics (LabNodeParams).
struct PublishLimits {
  std::uint64_t max_published = 0;          ///< [1] collisions published one by one
  double progress_period = 0.0;             ///< [s] of wall time between two RunProgress
  std::uint64_t progress_every_events = 0;  ///< [1] test hook: instead of the period, when > 0
};

/// Fills the state of every body after event from replay (for scenes above
/// CollisionEvent.FULL_STATE_MAX_BODIES, whose events carry none): positions at the event's
/// time, velocities and kinetic energies after it, the totals. Keeps event's storage.
inline void fillFullState(const collision_lab::core::BodyStateReplay& replay, collision_lab::CollisionEvent& event) {
  event.positions.resize(replay.size());
  for (std::size_t i = 0; i < replay.size(); ++i) event.positions[i] = replay.position(i, event.time);
  event.velocities_after = replay.velocities();
  event.kinetic_energy_after = replay.kineticEnergies();
  event.total_energy = replay.totalKineticEnergy();
  event.total_momentum = replay.momentum();
}

/// The per-collision messages of one run. Every CollisionEvent is recorded and drawn;
/// the first max_published also go out on collision_events and, as their plot
/// projections (live only, never recorded: docs/messages.md), on velocities and
/// energy_transfers. Past them, a RunProgress (live only) goes out at the first collision
/// not published and then at most every progress_period of wall time: a clock check per
/// collision, no allocation once its message has grown to the scene's size. Each is
/// refilled in the node's one message of its kind (buffers), whose storage is reused from
/// event to event and run to run.
class EventStream {
 public:
  /// fail_at_first_event: the test hook ~fail_runs_of_student (throws std::bad_alloc).
  EventStream(const RunTopics& topics, RunWriter& out, RunObserver* markers, const PublishLimits& limits,
              const collision_lab::core::Scene& scene, EventMessages& buffers, RunSoFar& progress,
              bool fail_at_first_event)
      : topics_(topics), out_(out), markers_(markers), limits_(limits), scene_(scene),
        msg_(buffers), progress_(progress), fail_(fail_at_first_event) {}

  /// An impact, with its model block where it has one.
  void operator()(const collision_lab::core::ImpactRecord& impact) {
    converter().impact(impact, msg_.event);
    sendWithPlots();
  }
  /// A collapse the event engine resolved.
  void operator()(const collision_lab::core::Collapse& collapse) {
    converter().collapse(collapse, msg_.event);
    sendWithPlots();
  }

  /// True when ~max_published_events cut the published stream.
  bool cut() const { return cut_; }

 private:
  /// The converter, made at the run's first event.
  SceneEventConverter& converter() {
    if (!converter_) converter_.emplace(scene_);
    return *converter_;
  }
  void sendWithPlots() {
    if (send(msg_.event)) {
      converter_->velocitiesMsg(msg_.event, msg_.velocities);
      topics_.velocities.publish(msg_.velocities);
      converter_->energyTransferMsg(msg_.event, msg_.energy);
      topics_.energies.publish(msg_.energy);
    }
    out_.record(std::move(msg_.event));
  }
  /// Stamps and draws msg, and publishes it unless the cap is reached (then, when due, the
  /// run's progress); true when published. The caller records it.
  bool send(collision_lab::CollisionEvent& msg) {
    if (fail_) throw std::bad_alloc();
    ++progress_.collisions;
    progress_.last_time = msg.time;
    out_.stamp(msg, msg.time);
    if (markers_) markers_->onCollisionEvent(msg);
    if (progress_.published == limits_.max_published) {
      if (progressDue()) publishProgress(msg);
      cut_ = true;
      return false;
    }
    topics_.events.publish(msg);
    ++progress_.published;
    return true;
  }
  /// At the first collision not published; then after progress_every_events more, or
  /// without that hook once progress_period has passed since the last RunProgress.
  bool progressDue() {
    if (!cut_) return true;
    if (limits_.progress_every_events > 0) return ++unpublished_since_progress_ >= limits_.progress_every_events;
    return std::chrono::steady_clock::now() >= next_progress_;
  }
  void publishProgress(const collision_lab::CollisionEvent& msg) {
    unpublished_since_progress_ = 0;
    next_progress_ = std::chrono::steady_clock::now() +
                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                         std::chrono::duration<double>(limits_.progress_period));
    collision_lab::RunProgress& p = msg_.progress;
    p.header = msg.header;
    p.run_id = msg.run_id;
    p.collisions = msg.index;
    p.time = msg.time;
    p.published = progress_.published;
    p.latest_event = msg;
    // The replay has the heat and, above FULL_STATE_MAX_BODIES, the state the event leaves out.
    p.energy_lost = converter_->replay().heat();
    if (p.latest_event.positions.empty()) fillFullState(converter_->replay(), p.latest_event);
    topics_.progress.publish(p);
  }

  const RunTopics& topics_;
  RunWriter& out_;
  RunObserver* markers_;
  PublishLimits limits_;
  const collision_lab::core::Scene& scene_;
  std::optional<SceneEventConverter> converter_;
  EventMessages& msg_;
  RunSoFar& progress_;
  bool fail_;
  bool cut_ = false;
  std::uint64_t unpublished_since_progress_ = 0;  ///< [1] since the last RunProgress
  std::chrono::steady_clock::time_point next_progress_;
};

}  // namespace collision_lab_ros
