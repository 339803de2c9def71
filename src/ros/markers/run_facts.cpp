// What kind of run it is, and the texts that say so (title, note, status line).
#include <algorithm>
#include <cmath>

#include "collision_lab/core/nbody/models.h"
#include "collision_lab/ros/markers/draw.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/run_view.h"

namespace collision_lab_ros::markers {

namespace {

bool simulatedStepByStep(const RunRecord& run) {
  return run.input().mode == collision_lab::InitialConditions::MODE_FULL &&
         !(run.summary && !run.summary->simulated);
}

}  // namespace

std::uint64_t Period::inPeriod(double t, std::uint64_t collisions) const {
  const std::uint64_t behind = before(t) * impacts;
  return std::min(impacts, collisions > behind ? collisions - behind : 0);
}

std::optional<Period> periodOf(const RunRecord& run) {
  if (run.bodies() != 3) return std::nullopt;  // before copying a large scene, frame after frame
  const auto period = collision_lab::core::wallToWallPeriod(toScene(run.input()));
  if (!period || !(endTime(run) > layout::kPeriodsToFold * period->time)) return std::nullopt;
  return Period{period->time, period->impacts};
}

std::string periodsSoFar(const Period& period, double t) {
  return "periods so far: " + withSeparators(period.before(t));
}

double indexAxisEnd(const RunRecord& run, const RunView& view) {
  if (const auto period = periodOf(run)) return static_cast<double>(period->impacts) + 1.0;
  const std::uint64_t n = simulatedStepByStep(run) ? run.collisions() : view.expected.value_or(run.collisions());
  return static_cast<double>(n) + 1.0;
}

std::optional<std::pair<std::uint64_t, std::vector<double>>> finalVelocitiesNotDrawn(const RunRecord& run) {
  if (simulatedStepByStep(run) && !(run.summary && run.summary->truncated)) return std::nullopt;
  if (run.summary && run.summary->simulated && !run.summary->truncated) {
    return std::make_pair(run.summary->collision_count, run.summary->final_velocities);
  }
  if (run.prediction && run.prediction->collision_count_defined && run.prediction->collision_count > run.collisions()) {
    return std::make_pair(run.prediction->collision_count, run.prediction->final_velocities);
  }
  return std::nullopt;
}

// The title and the note are the run's view description (RunView), the page's texts too.
std::string runTitle(const RunRecord& run) { return makeRunView(run).title; }

std::string runNote(const RunRecord& run) { return makeRunView(run).note; }

std::string statusLine(const RunView& view, const SceneState& state, const FrameClock& clock) {
  std::string s = "t = " + numberText(state.time, 6) + " s";
  // The collisions behind now (a replay passes them one by one), then the run's counter,
  // collapse, ring and box as the page says them; a run not simulated has no collisions to
  // count.
  if (view.not_simulated.empty()) s += "     collisions " + withSeparators(state.collisions);
  s += "     run: " + view.counter;
  for (const std::string* fact : {&view.collapse_brief, &view.ring, &view.box, &view.moving_wall}) {
    if (!fact->empty()) s += ";  " + *fact;
  }
  if (!clock.description.empty()) s += "     " + clock.description;
  return s;
}

}  // namespace collision_lab_ros::markers
