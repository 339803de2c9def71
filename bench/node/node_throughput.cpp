// collision_lab_node_throughput (issue 4, "Throughput of the whole node"). Over loopback it
// publishes K initial conditions as fast as it can to each target namespace in turn and
// measures runs per second and the latency from publishing a run to receiving its
// RunSummary (p50, p99), and how many runs were lost. Targets (private parameter
// ~targets) are namespaces holding a collision_lab_node (recording on or off) or a
// collision_lab_relay_node, the transport limit; every rate is also printed as a ratio to
// the relay's. Started by bench/node/node_throughput.launch, which sets everything up.
//
// Private parameters: ~targets (list of namespaces, the relay first), ~runs (K, 2000),
// ~rounds (targets are measured round-robin this many times; medians are reported, 3),
// ~scene masses/positions/velocities (a short scene), ~mode (InitialConditions.MODE_*, 0),
// ~timeout (s without progress before giving up, 20).
// Goal (printed as measured, not asserted): at least 80% of the relay's rate, nothing lost.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include <ros/ros.h>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/node_constants.h"

namespace {

struct TargetResult {
  std::string target;
  int sent = 0;
  int received = 0;
  int rejected = 0;
  double seconds = 0.0;  ///< first publish to last summary [s]
  double rate = 0.0;     ///< runs answered per second [1/s]
  double p50_ms = 0.0, p99_ms = 0.0;
};

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto index = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
  return values[std::min(index, values.size() - 1)];
}

class Client {
 public:
  Client(ros::NodeHandle& nh, const std::string& target, const std::string& run_prefix)
      : target_(target), prefix_(run_prefix) {
    pub_ = nh.advertise<collision_lab::InitialConditions>(
        target + "/" + collision_lab_ros::kInitialConditionsTopic, collision_lab_ros::kInputQueueSize);
    summary_sub_ = nh.subscribe(target + "/" + collision_lab_ros::kRunSummariesTopic,
                                collision_lab_ros::kOutputQueueSize, &Client::onSummary, this,
                                ros::TransportHints().tcpNoDelay());
    rejected_sub_ = nh.subscribe(target + "/" + collision_lab_ros::kRejectedTopic,
                                 collision_lab_ros::kOutputQueueSize, &Client::onRejected, this,
                                 ros::TransportHints().tcpNoDelay());
  }

  /// Waits for the links in both directions (the first message after advertise is lost
  /// otherwise). False after `timeout` seconds.
  bool waitConnected(double timeout) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
    while (ros::ok() && ros::WallTime::now() < end) {
      if (pub_.getNumSubscribers() > 0 && summary_sub_.getNumPublishers() > 0) return true;
      ros::WallDuration(0.05).sleep();
    }
    return false;
  }

  /// Publishes `count` runs back to back and waits until every one is answered or no
  /// answer came for `timeout` seconds.
  TargetResult run(const collision_lab::InitialConditions& scene, int count, double timeout) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      sent_at_.clear();
      latencies_.clear();
      received_ = rejected_ = 0;
      round_++;
    }
    TargetResult result;
    result.target = target_;
    const ros::WallTime start = ros::WallTime::now();
    for (int i = 0; i < count; ++i) {
      collision_lab::InitialConditions msg = scene;
      msg.run_id = prefix_ + "r" + std::to_string(round_) + "_" + std::to_string(i);
      msg.header.stamp = ros::Time::now();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        sent_at_[msg.run_id] = ros::WallTime::now();
      }
      pub_.publish(msg);
    }
    result.sent = count;
    int last_seen = -1;
    ros::WallTime last_progress = ros::WallTime::now();
    while (ros::ok()) {
      int done;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        done = received_ + rejected_;
        result.seconds = (last_answer_ - start).toSec();
      }
      if (done >= count) break;
      if (done != last_seen) {
        last_seen = done;
        last_progress = ros::WallTime::now();
      } else if ((ros::WallTime::now() - last_progress).toSec() > timeout) {
        break;
      }
      ros::WallDuration(0.001).sleep();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    result.received = received_;
    result.rejected = rejected_;
    result.rate = result.seconds > 0 ? result.received / result.seconds : 0.0;
    result.p50_ms = percentile(latencies_, 0.50) * 1e3;
    result.p99_ms = percentile(latencies_, 0.99) * 1e3;
    return result;
  }

 private:
  void answered(const std::string& run_id, bool rejected) {
    const ros::WallTime now = ros::WallTime::now();
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = sent_at_.find(run_id);
    if (it == sent_at_.end()) return;  // a warm-up run or another client's
    (rejected ? rejected_ : received_)++;
    if (!rejected) latencies_.push_back((now - it->second).toSec());
    last_answer_ = now;
    sent_at_.erase(it);
  }
  void onSummary(const collision_lab::RunSummary::ConstPtr& msg) { answered(msg->run_id, false); }
  void onRejected(const collision_lab::Rejected::ConstPtr& msg) { answered(msg->run_id, true); }

  std::string target_, prefix_;
  ros::Publisher pub_;
  ros::Subscriber summary_sub_, rejected_sub_;
  std::mutex mutex_;
  std::unordered_map<std::string, ros::WallTime> sent_at_;
  std::vector<double> latencies_;
  int received_ = 0, rejected_ = 0, round_ = 0;
  ros::WallTime last_answer_;
};

template <class T>
std::vector<T> param(const ros::NodeHandle& pnh, const std::string& name, std::vector<T> fallback) {
  pnh.getParam(name, fallback);
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_node_throughput");
  ros::NodeHandle nh, pnh("~");
  const auto targets = param<std::string>(pnh, "targets", {"relay", "norecord", "record"});
  const int runs = pnh.param("runs", 2000);
  const int rounds = std::max(1, pnh.param("rounds", 3));
  const double timeout = pnh.param("timeout", 20.0);
  const auto masses = param<double>(pnh, "masses", {1.0, 2.0, 3.0});
  const auto positions = param<double>(pnh, "positions", {1.0, 0.0, -1.5});
  const auto velocities = param<double>(pnh, "velocities", {-1.0, 0.0, 1.0});
  collision_lab::InitialConditions scene;
  scene.mode = static_cast<std::uint8_t>(pnh.param("mode", 0));
  for (int i = 0; i < 3; ++i) {
    scene.masses[i] = masses.at(i);
    scene.positions[i] = positions.at(i);
    scene.velocities[i] = velocities.at(i);
  }
  // Run ids unique per invocation: a recording lab node rejects an id whose bag exists.
  const std::string prefix = "tp" + std::to_string(::getpid()) + "_" +
                             std::to_string(static_cast<long long>(ros::WallTime::now().toSec())) + "_";

  ros::AsyncSpinner spinner(1);
  spinner.start();
  std::vector<std::unique_ptr<Client>> clients;
  for (const auto& target : targets) {
    clients.push_back(std::make_unique<Client>(nh, target, prefix + target + "_"));
    if (!clients.back()->waitConnected(30.0)) {
      ROS_ERROR_STREAM("no connection to " << target << " within 30 s");
      return 1;
    }
    clients.back()->run(scene, std::min(runs, 50), timeout);  // warm-up: connections, caches, bag directory
  }
  std::vector<std::vector<TargetResult>> rounds_of(targets.size());
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t t = 0; t < targets.size(); ++t) {
      ROS_INFO_STREAM("round " << round + 1 << "/" << rounds << ": " << targets[t] << ", " << runs << " runs");
      rounds_of[t].push_back(clients[t]->run(scene, runs, timeout));
    }
  }
  // Per target: median rate and latencies over the rounds, all runs lost summed.
  std::vector<TargetResult> results;
  for (std::size_t t = 0; t < targets.size(); ++t) {
    auto& all = rounds_of[t];
    std::sort(all.begin(), all.end(), [](const TargetResult& a, const TargetResult& b) { return a.rate < b.rate; });
    TargetResult median_round = all[all.size() / 2];
    std::vector<double> p50, p99;
    median_round.sent = median_round.received = median_round.rejected = 0;
    for (const auto& r : all) {
      p50.push_back(r.p50_ms);
      p99.push_back(r.p99_ms);
      median_round.sent += r.sent;
      median_round.received += r.received;
      median_round.rejected += r.rejected;
    }
    median_round.p50_ms = percentile(p50, 0.5);
    median_round.p99_ms = percentile(p99, 0.5);
    results.push_back(median_round);
  }

  const double relay_rate = results.front().rate;
  std::printf("\nNode throughput over loopback: %d rounds of %d runs per target (medians over rounds), "
              "scene masses (%g, %g, %g), mode %d\n", rounds, runs, masses[0], masses[1], masses[2], scene.mode);
  std::printf("%-12s %8s %9s %9s %12s %10s %10s %12s\n", "target", "sent", "answered", "lost", "runs/s",
              "p50 [ms]", "p99 [ms]", "vs relay");
  bool goal = true;
  for (const auto& r : results) {
    const int lost = r.sent - r.received - r.rejected;
    const double ratio = relay_rate > 0 ? r.rate / relay_rate : 0.0;
    std::printf("%-12s %8d %9d %9d %12.0f %10.2f %10.2f %11.0f%%\n", r.target.c_str(), r.sent, r.received, lost,
                r.rate, r.p50_ms, r.p99_ms, 100 * ratio);
    if (r.target != targets.front() && (ratio < 0.8 || lost != 0 || r.rejected != 0)) goal = false;
  }
  std::printf("Goal: every lab node at >= 80%% of the relay's rate with nothing lost or rejected: %s "
              "(measured, not asserted)\n", goal ? "met" : "missed");
  spinner.stop();
  return 0;
}
