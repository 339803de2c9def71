#include "lab_node_shared.h"

#include <ctime>
#include <sstream>

namespace collision_lab_ros {

// gmtime_r, not std::gmtime's shared buffer: the service threads call it concurrently.
std::string utcStamp(const char* format) {
  char buffer[32];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(buffer, sizeof buffer, format, &utc);
  return buffer;
}

std::string predictedText(const collision_lab::RunSummary& summary) {
  std::ostringstream text;
  if (summary.predicted_collision_count_defined) {
    text << "predicted " << summary.predicted_collision_count;
  } else if (summary.infinite_collisions) {
    text << "predicted: infinitely many collisions (" << summary.model_name << ")";
  } else {
    text << "no count predicted by " << summary.model_name;
  }
  if (summary.collapsed) text << ", collapsed at t = " << summary.collapse_time << " s";
  return text.str();
}

ros::Time stampNow() {
  const ros::Time now = ros::Time::now();
  if (now >= ros::TIME_MIN) return now;
  const ros::WallTime wall = ros::WallTime::now();
  return ros::Time(wall.sec, wall.nsec);
}

collision_lab::core::SceneRunOptions sceneRunOptions(collision_lab::core::RunMode mode, std::uint64_t max_collisions,
                                                     bool simulate_to_cap) {
  namespace core = collision_lab::core;
  core::SceneRunOptions options;
  options.lab.max_collisions = max_collisions;
  options.lab.events = mode == core::RunMode::kFull ? core::EventPolicy::all() : core::EventPolicy::none();
  options.lab.mode = mode;
  options.simulate_to_cap = simulate_to_cap;
  options.keep_events = false;
  return options;
}

}  // namespace collision_lab_ros
