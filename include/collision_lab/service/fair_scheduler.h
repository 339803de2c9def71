// The lab node's queue of accepted runs (ROS-free, not thread-safe: the owner locks).
//
// Two lanes, short and long. In each lane every student has a FIFO queue, and the
// students are served round robin: a student's tenth waiting run goes after a
// classmate's first. Anonymous runs (student "") count as one student. A worker of the
// short lane takes only short runs; any other worker takes a short run first when one
// waits (short runs are quick), else a long one.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "collision_lab/core/scene_run.h"

namespace collision_lab {
namespace service {

enum class Lane { kShort, kLong };

inline const char* laneName(Lane lane) { return lane == Lane::kShort ? "short" : "long"; }

/// What makes a run short (the node's ~short_max_collisions, ~short_max_seconds).
struct LaneLimits {
  std::uint64_t short_max_collisions = 100'000;  ///< [1] impacts, where the plan counts them
  double short_max_seconds = 1.0;                ///< [s] estimated compute, where it does not
  std::uint64_t probe_impacts = 256;             ///< [1] impacts the estimate times
};

/// Short when the run's planned impacts (core::plannedImpacts: the core's own decision) are
/// at most limits.short_max_collisions. When the plan cannot count them, by the run's cost:
/// the engine's first limits.probe_impacts impacts are run and timed (core::runScene,
/// summary only, nothing published; the plan's own time left out); short when the run ends
/// within them, or when its cap is at most short_max_collisions (what it publishes and
/// records is bounded as a counted run's) and the cap's impacts at the measured rate take
/// at most limits.short_max_seconds; else long. The probe costs at most probe_impacts
/// impacts of the intake's time.
inline Lane chooseLane(const core::ScenePlan& plan, const core::SceneRunOptions& options, const LaneLimits& limits) {
  if (const auto impacts = core::plannedImpacts(plan, options)) {
    return *impacts <= limits.short_max_collisions ? Lane::kShort : Lane::kLong;
  }
  core::SceneRunOptions probe = options;
  probe.lab.max_collisions = std::min(options.lab.max_collisions, limits.probe_impacts);
  probe.lab.mode = core::RunMode::kSummaryOnly;
  probe.keep_events = false;
  probe.cancel = nullptr;
  const core::SceneRunResult timed = core::runScene(plan, probe);
  if (!timed.simulation.truncated) return Lane::kShort;  // it ended within the probe
  if (options.lab.max_collisions > limits.short_max_collisions) return Lane::kLong;
  const double seconds = std::max(timed.compute_time_s - plan.plan_time_s, 1e-9);
  const double rate = static_cast<double>(timed.simulation.impact_count) / seconds;  // [1/s]
  return static_cast<double>(options.lab.max_collisions) <= rate * limits.short_max_seconds ? Lane::kShort : Lane::kLong;
}

template <class Job>
class FairScheduler {
 public:
  struct Entry {
    std::string run_id;
    std::string student;
    Lane lane = Lane::kLong;
    Job job;
  };

  /// Queues job; returns the runs ahead of it in its lane's serving order [1].
  std::size_t push(Entry entry) {
    LaneQueue& lane = lanes_[index(entry.lane)];
    const std::size_t ahead = lane.aheadOfNext(entry.student);
    lane.push(std::move(entry));
    return ahead;
  }

  /// The next run for a worker: short lane only (short_only), else short first, then long.
  std::optional<Entry> pop(bool short_only) {
    if (auto entry = lanes_[index(Lane::kShort)].pop()) return entry;
    if (short_only) return std::nullopt;
    return lanes_[index(Lane::kLong)].pop();
  }

  /// True when pop(short_only) would give a run.
  bool ready(bool short_only) const {
    return !lanes_[index(Lane::kShort)].empty() || (!short_only && !lanes_[index(Lane::kLong)].empty());
  }

  /// Takes the waiting run run_id out of the queue; empty when no such run waits.
  std::optional<Entry> remove(const std::string& run_id) {
    for (LaneQueue& lane : lanes_) {
      if (auto entry = lane.remove(run_id)) return entry;
    }
    return std::nullopt;
  }

  /// The first `limit` waiting runs, short lane first, each lane in its serving order.
  std::vector<const Entry*> order(std::size_t limit = std::numeric_limits<std::size_t>::max()) const {
    std::vector<const Entry*> ordered;
    for (const LaneQueue& lane : lanes_) lane.appendOrder(ordered, limit);
    return ordered;
  }

  /// Takes every waiting run out (the node's shutdown).
  std::vector<Entry> drain() {
    std::vector<Entry> drained;
    for (LaneQueue& lane : lanes_) {
      while (auto entry = lane.pop()) drained.push_back(std::move(*entry));
    }
    return drained;
  }

  std::size_t size() const { return lanes_[0].size() + lanes_[1].size(); }

 private:
  static std::size_t index(Lane lane) { return lane == Lane::kShort ? 0 : 1; }

  /// One lane: per-student FIFOs, served in the order of turns_ (round robin).
  class LaneQueue {
   public:
    bool empty() const { return turns_.empty(); }
    std::size_t size() const { return size_; }

    /// Runs ahead of a run of student pushed now: the student's waiting runs k, plus, of
    /// every other student, as many runs as get served before the student's (k+1)-th
    /// round: min(count, k + 1) for those whose turn comes first, min(count, k) after.
    std::size_t aheadOfNext(const std::string& student) const {
      const auto own = queues_.find(student);
      const std::size_t k = own == queues_.end() ? 0 : own->second.size();
      std::size_t ahead = k;
      bool before = true;  // students whose turn comes before student's
      for (const std::string& other : turns_) {
        if (other == student) {
          before = false;
          continue;
        }
        ahead += std::min(queues_.at(other).size(), before ? k + 1 : k);
      }
      return ahead;
    }

    void push(Entry entry) {
      std::deque<Entry>& queue = queues_[entry.student];
      if (queue.empty()) turns_.push_back(entry.student);
      queue.push_back(std::move(entry));
      ++size_;
    }

    std::optional<Entry> pop() {
      if (turns_.empty()) return std::nullopt;
      const std::string student = std::move(turns_.front());
      turns_.pop_front();
      auto it = queues_.find(student);
      Entry entry = std::move(it->second.front());
      it->second.pop_front();
      if (it->second.empty()) {
        queues_.erase(it);
      } else {
        turns_.push_back(student);
      }
      --size_;
      return entry;
    }

    std::optional<Entry> remove(const std::string& run_id) {
      for (auto it = queues_.begin(); it != queues_.end(); ++it) {
        auto& queue = it->second;
        const auto found = std::find_if(queue.begin(), queue.end(), [&](const Entry& e) { return e.run_id == run_id; });
        if (found == queue.end()) continue;
        Entry entry = std::move(*found);
        queue.erase(found);
        if (queue.empty()) {
          turns_.erase(std::find(turns_.begin(), turns_.end(), it->first));
          queues_.erase(it);
        }
        --size_;
        return entry;
      }
      return std::nullopt;
    }

    void appendOrder(std::vector<const Entry*>& ordered, std::size_t limit) const {
      for (std::size_t round = 0;; ++round) {
        bool any = false;
        for (const std::string& student : turns_) {
          const std::deque<Entry>& queue = queues_.at(student);
          if (ordered.size() >= limit) return;
          if (round < queue.size()) {
            ordered.push_back(&queue[round]);
            any = true;
          }
        }
        if (!any) return;
      }
    }

   private:
    std::map<std::string, std::deque<Entry>> queues_;  ///< non-empty queues only
    std::deque<std::string> turns_;                    ///< students with waiting runs, next first
    std::size_t size_ = 0;
  };

  LaneQueue lanes_[2];
};

}  // namespace service
}  // namespace collision_lab
