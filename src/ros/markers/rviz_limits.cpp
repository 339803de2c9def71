// Deleting markers, and rviz's limits as a last guard on every array the view publishes
// (see enforceRvizLimits in marker_builder.h).
#include <algorithm>
#include <cmath>
#include <iterator>

#include "collision_lab/ros/marker_builder.h"

namespace collision_lab_ros {

using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;

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
