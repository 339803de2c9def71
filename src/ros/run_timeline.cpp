#include "collision_lab/ros/run_timeline.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

namespace collision_lab_ros {

namespace {
constexpr double kOrdinaryMin = 1e-3;  ///< [s] first contacts in [min, max] keep scale 1
constexpr double kOrdinaryMax = 1e3;   ///< [s]
constexpr int kMaxExponent = 300;      ///< 10^+-300 are normal doubles
constexpr std::uint64_t kNsPerS = 1'000'000'000;
}  // namespace

std::optional<double> firstContactTime(const collision_lab::core::Scene& scene) {
  std::optional<double> first;
  for (std::size_t p = 0; p < scene.pairCount(); ++p) {
    const double closing = scene.velocities[p + 1] - scene.velocities[p];
    if (!(closing > 0)) continue;
    const double t = (scene.positions[p] - scene.positions[p + 1]) / closing;
    if (!first || t < *first) first = t;
  }
  return first;
}

double chooseTimelineScale(const std::optional<double>& first_contact) {
  if (!first_contact) return 1.0;
  const double t = *first_contact;
  if (t >= kOrdinaryMin && t <= kOrdinaryMax) return 1.0;
  // log10 of 0 is -inf and of inf is inf; both end at a clamp.
  const double exponent = std::floor(std::log10(t));
  const double k = std::clamp(std::isnan(exponent) ? 0.0 : exponent,
                              static_cast<double>(-kMaxExponent), static_cast<double>(kMaxExponent));
  // The double nearest 10^-k, as the literal 1e-k spells it (strtod rounds correctly).
  return std::strtod(("1e" + std::to_string(-static_cast<int>(k))).c_str(), nullptr);
}

ros::Time RunTimeline::stamp(double t) {
  double offset = std::max(scale_ * t, 0.0);
  if (!(offset <= kMaxOffset)) {  // also NaN
    offset = kMaxOffset;
    saturated_ = true;
  }
  // Whole seconds and the exact fractional rest, so that the offset is rounded to the
  // nanosecond once.
  const double whole = std::floor(offset);
  const std::uint64_t offset_ns = static_cast<std::uint64_t>(whole) * kNsPerS +
                                  static_cast<std::uint64_t>(std::llround((offset - whole) * 1e9));
  const std::uint64_t max_ns = ros::TIME_MAX.toNSec();
  const std::uint64_t start_ns = start_.toNSec();
  if (offset_ns > max_ns - start_ns) {
    saturated_ = true;
    return ros::TIME_MAX;
  }
  ros::Time result;
  return result.fromNSec(start_ns + offset_ns);
}

}  // namespace collision_lab_ros
