// Test client for the marker view's topics: collects what the animation shows, with
// waits that end at a timeout with a clear message (never a sleep).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include "collision_lab/ros/node_constants.h"

namespace collision_lab_test {

/// Spins the global queue until done() or timeout [s] of wall time; returns done().
inline bool spinUntil(const std::function<bool()>& done, double timeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && !done() && ros::WallTime::now() < deadline) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.05));
  }
  return done();
}

/// The number after `key` in text, digits with ',' separators; -1 when absent.
inline long long numberAfter(const std::string& text, const std::string& key) {
  const std::size_t at = text.find(key);
  if (at == std::string::npos) return -1;
  long long n = -1;
  for (std::size_t k = at + key.size(); k < text.size(); ++k) {
    if (text[k] >= '0' && text[k] <= '9') {
      n = (n < 0 ? 0 : n * 10) + (text[k] - '0');
    } else if (text[k] != ',' || n < 0) {
      break;
    }
  }
  return n;
}

/// A MarkerArray with its connection header (which says whether the topic is latched).
using MarkerEvent = ros::MessageEvent<visualization_msgs::MarkerArray const>;
using MarkerEventCallback = boost::function<void(const MarkerEvent&)>;

inline bool latched(const MarkerEvent& event) {
  const auto& header = event.getConnectionHeader();
  const auto it = header.find("latching");
  return it != header.end() && it->second == "1";
}

/// What the animation has shown so far.
struct AnimationWatcher {
  explicit AnimationWatcher(ros::NodeHandle nh) {
    sub = nh.subscribe<visualization_msgs::MarkerArray, const MarkerEvent&>(
        collision_lab_ros::kAnimatedMarkersTopic, 100, MarkerEventCallback([this](const MarkerEvent& event) {
          is_latched = latched(event);
          ++frames;
          for (const auto& m : event.getMessage()->markers) {
            if (m.ns == "labels" && m.id == 3) {
              status = m.text;
              largest_count = std::max(largest_count, numberAfter(m.text, "collisions "));
            }
            if (m.ns == "hint" && m.id == 0) hint = m.text;
            if (m.ns == "rejected" && m.id == 0) banner = m.text;
          }
        }));
  }

  ros::Subscriber sub;
  std::uint64_t frames = 0;
  bool is_latched = false;
  std::string status, hint, banner;  ///< the newest of each
  long long largest_count = -1;      ///< the largest collision counter shown
};

}  // namespace collision_lab_test
