// Checks shared by the marker unit tests: what rviz 1.14 accepts and survives, and one
// marker per namespace and id.
#pragma once

#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>
#include <algorithm>

#include <gtest/gtest.h>
#include <visualization_msgs/MarkerArray.h>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/ids.h"

namespace marker_checks {

using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;

inline bool isLine(const Marker& m) { return m.type == Marker::LINE_STRIP || m.type == Marker::LINE_LIST; }

/// What rviz 1.14 accepts and survives (see kRvizMaxLinePoints and rviz's marker_utils.cpp).
inline void expectFitForRviz(const MarkerArray& array) {
  std::set<std::pair<std::string, int>> ids;
  for (const auto& m : array.markers) {
    if (m.action != Marker::ADD) continue;
    EXPECT_TRUE(ids.insert({m.ns, m.id}).second) << "duplicate " << m.ns << "/" << m.id;
    EXPECT_TRUE(std::isfinite(m.pose.position.x) && std::isfinite(m.pose.position.y)) << m.ns;
    for (const auto& p : m.points) {
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << m.ns << "/" << m.id;
    }
    if (!m.colors.empty()) {
      EXPECT_EQ(m.colors.size(), m.points.size()) << m.ns << "/" << m.id;
    }
    if (isLine(m)) {
      EXPECT_GE(m.points.size(), 2u) << m.ns << "/" << m.id;
      EXPECT_LE(m.points.size(), 16384u) << m.ns << "/" << m.id;  // BillboardLine MAX_ELEMENTS
      EXPECT_GT(m.scale.x, 0) << m.ns;
    }
    if (m.type == Marker::LINE_LIST) {
      EXPECT_EQ(m.points.size() % 2, 0u) << m.ns << "/" << m.id;
    }
    if (m.type == Marker::TRIANGLE_LIST) {
      EXPECT_EQ(m.points.size() % 3, 0u) << m.ns;
    }
    if (m.type == Marker::SPHERE_LIST || m.type == Marker::CUBE_LIST) {
      EXPECT_FALSE(m.points.empty()) << m.ns << "/" << m.id;
    }
    if (m.type == Marker::TEXT_VIEW_FACING) {
      EXPECT_NE(m.text.find_first_not_of(" \n"), std::string::npos) << m.ns << "/" << m.id;
      EXPECT_GT(m.scale.z, 0);
    }
  }
  MarkerArray copy = array;
  EXPECT_EQ(collision_lab_ros::enforceRvizLimits(copy), 0u);
}

/// rviz keeps one marker per namespace and id: a second one in the same array would
/// replace the first, and a view would lose a part without a word.
inline void expectOneMarkerPerId(const MarkerArray& array) {
  std::set<std::pair<std::string, int>> seen;
  for (const auto& m : array.markers) EXPECT_TRUE(seen.insert({m.ns, m.id}).second) << m.ns << "/" << m.id;
}

/// Where a TEXT_VIEW_FACING marker's glyphs lie [rviz units], centred on its position:
/// rviz's font is about 0.42 text heights wide per character, its lines 1.25 heights apart,
/// each glyph about one height tall (measured on the headless screenshots: 60 characters
/// at height 0.29 spanned 7.1 units).
struct TextBox {
  double left, right, bottom, top;
};
inline TextBox textBox(const Marker& m) {
  std::size_t longest = 0, lines = 1, start = 0;
  for (std::size_t end = m.text.find('\n');; end = m.text.find('\n', start)) {
    longest = std::max(longest, (end == std::string::npos ? m.text.size() : end) - start);
    if (end == std::string::npos) break;
    start = end + 1, ++lines;
  }
  const double h = m.scale.z, half_w = 0.21 * h * static_cast<double>(longest);
  const double half_h = (1.25 * h * static_cast<double>(lines - 1) + h) / 2;
  return {m.pose.position.x - half_w, m.pose.position.x + half_w, m.pose.position.y - half_h, m.pose.position.y + half_h};
}

/// Every text lies across the screen of rviz/collision_lab.rviz (x in [-10.7, 16.3]):
/// rviz cuts a text at the edge ("1.96e+03" lost its last digits).
inline void expectTextsOnScreen(const MarkerArray& array) {
  for (const Marker& m : array.markers) {
    if (m.type != Marker::TEXT_VIEW_FACING || m.action != Marker::ADD) continue;
    const TextBox box = textBox(m);
    EXPECT_GE(box.left, -10.7 - 1e-9) << m.ns << "/" << m.id << " '" << m.text << "'";
    EXPECT_LE(box.right, 16.3 + 1e-9) << m.ns << "/" << m.id << " '" << m.text << "'";
  }
}

inline bool apart(const TextBox& a, const TextBox& b) {
  return a.right <= b.left || b.right <= a.left || a.top <= b.bottom || b.top <= a.bottom;
}

/// `text` lies within [left, right] and overlaps no other text of the arrays.
inline void expectTextClear(const Marker& text, double left, double right, const std::vector<const MarkerArray*>& arrays) {
  const TextBox a = textBox(text);
  EXPECT_GE(a.left, left) << text.ns << "/" << text.id << " '" << text.text << "'";
  EXPECT_LE(a.right, right) << text.ns << "/" << text.id << " '" << text.text << "'";
  for (const MarkerArray* array : arrays) {
    for (const Marker& m : array->markers) {
      if (m.type != Marker::TEXT_VIEW_FACING || m.action != Marker::ADD || (m.ns == text.ns && m.id == text.id)) continue;
      const TextBox b = textBox(m);
      const bool apart = a.right <= b.left || b.right <= a.left || a.top <= b.bottom || b.top <= a.bottom;
      EXPECT_TRUE(apart) << "'" << text.text << "' overlaps " << m.ns << "/" << m.id << " '" << m.text << "'";
    }
  }
}

inline const Marker* find(const MarkerArray& array, const std::string& ns, int id) {
  for (const auto& m : array.markers) {
    if (m.ns == ns && m.id == id) return &m;
  }
  return nullptr;
}

/// The velocity plot's legend promises closed-form dots exactly when some are drawn (ns
/// "plot", ids kPlotPredicted + body in each panel).
inline void expectLegendMatchesDots(const MarkerArray& fixed) {
  using namespace collision_lab_ros::markers;
  bool dots = false;
  for (const auto& m : fixed.markers) {
    const int in_panel = m.id % kPlotPanelStride;
    dots = dots || (m.ns == ns::kPlot && m.type == Marker::SPHERE_LIST && in_panel >= kPlotPredicted &&
                    in_panel < kPlotPaper && !m.points.empty());
  }
  const Marker* legend = find(fixed, ns::kPlot, kPlotLegend);
  ASSERT_TRUE(legend);
  EXPECT_EQ(legend->text.find("dots: closed form") != std::string::npos, dots) << legend->text;
}

}  // namespace marker_checks
