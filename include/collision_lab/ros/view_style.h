// The view model's style, which the rviz markers and the page share: numbers in one
// written style, and the colour of a velocity. Draws nothing (no marker types).
#pragma once

#include <cstdint>
#include <string>

#include "collision_lab/ros/markers/layout.h"
#include "collision_lab/ros/run_record.h"

namespace collision_lab_ros::markers {

/// value printed by fmt (one printf conversion: %g, %e or %f, with text around it) in one
/// number style with the page: "4.68×10^11", "169,548".
std::string format(const char* fmt, double value);
/// 31415 -> "31,415".
std::string withSeparators(std::uint64_t n);
/// Largest |v| [m/s] of the finite bodies at the start (1 when all are at rest): the
/// scale of the colour by velocity (RunView::colour_scale).
double velocityScale(const RunRecord& run);
/// Velocity v [m/s] on a diverging map: blue at -v_max, purple at 0, red at +v_max
/// (clipped beyond).
Rgba velocityRgb(double v, double v_max);

}  // namespace collision_lab_ros::markers
