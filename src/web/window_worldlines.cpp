#include "collision_lab/web/window_worldlines.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <rosbag/bag.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/core/nbody/body_state_replay.h"
#include "collision_lab/ros/bag_reading.h"
#include "collision_lab/ros/run_record.h"
#include "collision_lab/ros/msg_conversion.h"

namespace collision_lab_web {

WindowWorldlines windowWorldlines(const std::string& bag_path, double from, double to,
                                  const std::vector<std::size_t>& bodies, std::size_t max_vertices) {
  using collision_lab::CollisionEvent, collision_lab::InitialConditions;
  if (!(from >= 0.0 && from < to)) throw std::invalid_argument("the window must have 0 <= from < to");
  collision_lab_ros::ReadableBag bag = collision_lab_ros::openBagForReading(bag_path);
  rosbag::View starts(*bag, rosbag::TypeQuery(ros::message_traits::datatype<InitialConditions>()));
  std::optional<collision_lab::core::BodyStateReplay> state;
  for (const rosbag::MessageInstance& m : starts) {
    if (const auto initial = m.instantiate<InitialConditions>()) {
      if (initial->ring > 0) throw std::invalid_argument("a ring's window is not drawn (its lines wrap at the seam)");
      state.emplace(initial->masses, initial->positions, initial->velocities);
      break;
    }
  }
  if (!state) throw std::runtime_error(bag_path + " has no InitialConditions");
  std::vector<std::size_t> shown;
  for (std::size_t b : bodies) {
    if (b < state->size()) shown.push_back(b);
  }
  std::vector<std::size_t> line_of(state->size(), shown.size());
  for (std::size_t k = 0; k < shown.size(); ++k) line_of[shown[k]] = k;
  std::vector<collision_lab_ros::Envelope> lines(shown.size(), collision_lab_ros::Envelope(max_vertices));
  // The lines' x is the time since `from`, so that the columns of a long line divide the
  // window, not the run from t = 0.
  const auto addAll = [&](double t) {
    for (std::size_t k = 0; k < shown.size(); ++k) lines[k].add(t - from, state->position(shown[k], t));
  };
  bool started = false;
  rosbag::View events(*bag, rosbag::TypeQuery(ros::message_traits::datatype<CollisionEvent>()));
  for (const rosbag::MessageInstance& m : events) {
    const auto event = m.instantiate<CollisionEvent>();
    if (!event) continue;
    if (event->time > to) break;
    if (event->time >= from && !started) {
      addAll(from);
      started = true;
    }
    if (!collision_lab_ros::replayEvent(*state, *event) || !started) continue;
    for (std::size_t k = 0; k < state->movedCount(); ++k) {
      const std::size_t body = state->firstMoved() + k;
      if (body < line_of.size() && line_of[body] < shown.size()) {
        lines[line_of[body]].add(event->time - from, state->position(body, event->time));
      }
    }
  }
  if (!started) addAll(from);
  addAll(to);
  WindowWorldlines out;
  out.from = from, out.to = to;
  for (std::size_t k = 0; k < shown.size(); ++k) {
    out.exact = out.exact && lines[k].exact();
    WindowLine line;
    line.body = shown[k];
    for (const auto& v : lines[k].polyline()) line.points.emplace_back(from + v.x, v.y);
    out.lines.push_back(std::move(line));
  }
  return out;
}

}  // namespace collision_lab_web
