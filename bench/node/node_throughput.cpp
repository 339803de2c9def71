// collision_lab_node_throughput (issues 4 and 13, "Throughput of the whole node"). Over
// loopback it publishes K initial conditions as fast as it can to each target namespace in
// turn and measures runs per second, the latency from publishing a run to receiving its
// RunSummary (p50, p99), and how many runs and messages were lost (it subscribes to every
// per-run topic and counts what each summary announces). Targets (private parameter
// ~targets) are namespaces holding a collision_lab_node (recording on or off) or a
// collision_lab_relay_node, the fair anchor that publishes the same messages pre-built;
// every rate is also printed as a ratio to the relay's. Started by
// bench/node/node_throughput.launch, which sets everything up.
//
// Private parameters: ~targets (list of namespaces, the relay first), ~runs (K, 2000),
// ~rounds (targets are measured round-robin this many times; medians are reported, and
// each target's ratio to the relay is the median of its per-round ratios, 3),
// ~masses/~positions/~velocities (a short scene), ~mode (InitialConditions.MODE_*, 0),
// ~timeout (s without progress before giving up, 20), ~compute_target (the lab node
// without recording, "norecord"), ~recording_target (the recording one, "record").
// Goals (printed as `goal:` lines, measured, not asserted): the compute target at >= 80%
// of the relay's rate (the median over the rounds of its rate over the relay's in the
// same round) with nothing lost; the recording target's hand-over time per run
// (its /diagnostics) <= 100 us.
#include <unistd.h>

#include <fstream>
#include <sstream>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <diagnostic_msgs/DiagnosticArray.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Velocities.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/node_constants.h"

namespace {

struct TargetResult {
  std::string target;
  int sent = 0;
  int received = 0;
  int rejected = 0;
  long messages = 0;     ///< per-run messages received (predictions to summaries)
  long announced = 0;    ///< what the summaries announce: 1 + 3 * published_events + 1 each
  double seconds = 0.0;  ///< first publish to last summary [s]
  double rate = 0.0;     ///< runs answered per second [1/s]
  double p50_ms = 0.0, p99_ms = 0.0;
};

/// The process id of the node that publishes `topic` (the one a target serves), or 0: the
/// master names the publisher, whose own XML-RPC API gives its pid.
int pidOfPublisher(const std::string& topic) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", args, result, payload, false)) return 0;
  std::string node;
  for (int i = 0; i < payload[0].size() && node.empty(); ++i) {  // publishers: [topic, [nodes]]
    if (std::string(payload[0][i][0]) == topic && payload[0][i][1].size() > 0) node = std::string(payload[0][i][1][0]);
  }
  if (node.empty()) return 0;
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, false)) return 0;
  std::string host;
  std::uint32_t port = 0;
  if (!ros::network::splitURI(std::string(payload), host, port)) return 0;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue caller, answer;
  caller[0] = ros::this_node::getName();
  if (!client.execute("getPid", caller, answer) || answer.getType() != XmlRpc::XmlRpcValue::TypeArray) return 0;
  return static_cast<int>(answer[2]);
}

/// CPU time (user + system, all threads) that process `pid` has used [s]; 0 if unknown.
double processCpuSeconds(int pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (pid <= 0 || !std::getline(stat, line)) return 0.0;
  std::istringstream fields(line.substr(line.rfind(')') + 2));  // after "pid (comm) "
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int k = 3; k <= 15 && fields >> field; ++k) {  // fields 14 and 15: utime, stime in clock ticks
    if (k == 14) utime = std::stoull(field);
    if (k == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto index = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
  return values[std::min(index, values.size() - 1)];
}

/// The median of values: the middle one, or the mean of the two middle ones.
double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t half = values.size() / 2;
  return values.size() % 2 ? values[half] : (values[half - 1] + values[half]) / 2;
}

/// Ratios as whole percent, in order: "78 81 69".
std::string percentList(const std::vector<double>& ratios) {
  std::string list;
  for (const double ratio : ratios) {
    if (!list.empty()) list += ' ';
    list += std::to_string(static_cast<long>(std::lround(100 * ratio)));
  }
  return list;
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
    // Every per-run topic, as a plotting client would: the target serializes and sends
    // every message, and the counts show that nothing is lost.
    count_subs_.push_back(countOn<collision_lab::Prediction>(nh, collision_lab_ros::kPredictionsTopic));
    count_subs_.push_back(countOn<collision_lab::CollisionEvent>(nh, collision_lab_ros::kCollisionEventsTopic));
    count_subs_.push_back(countOn<collision_lab::Velocities>(nh, collision_lab_ros::kVelocitiesTopic));
    count_subs_.push_back(countOn<collision_lab::EnergyTransfer>(nh, collision_lab_ros::kEnergyTransfersTopic));
    rejected_sub_ = nh.subscribe(target + "/" + collision_lab_ros::kRejectedTopic,
                                 collision_lab_ros::kOutputQueueSize, &Client::onRejected, this,
                                 ros::TransportHints().tcpNoDelay());
  }

  /// Waits for the links in both directions (the first message after advertise is lost
  /// otherwise). False after `timeout` seconds.
  bool waitConnected(double timeout) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
    while (ros::ok() && ros::WallTime::now() < end) {
      bool all = pub_.getNumSubscribers() > 0 && summary_sub_.getNumPublishers() > 0;
      for (const auto& sub : count_subs_) all = all && sub.getNumPublishers() > 0;
      if (all) return true;
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
      messages_ = announced_ = 0;
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
      if (done >= count && messagesDone()) break;
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
    result.messages = messages_;
    result.announced = announced_;
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
  void onSummary(const collision_lab::RunSummary::ConstPtr& msg) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (sent_at_.count(msg->run_id)) ++messages_, announced_ += 2 + 3 * static_cast<long>(msg->published_events);
    }
    answered(msg->run_id, false);
  }
  bool messagesDone() {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_ >= announced_;
  }
  template <class Message>
  ros::Subscriber countOn(ros::NodeHandle& nh, const std::string& topic) {
    return nh.subscribe<Message>(target_ + "/" + topic, collision_lab_ros::kOutputQueueSize,
                                 [this](const typename Message::ConstPtr& msg) {
                                   if (msg->run_id.compare(0, prefix_.size(), prefix_) != 0) return;
                                   std::lock_guard<std::mutex> lock(mutex_);
                                   ++messages_;
                                 }, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  }
  void onRejected(const collision_lab::Rejected::ConstPtr& msg) { answered(msg->run_id, true); }

  std::string target_, prefix_;
  ros::Publisher pub_;
  ros::Subscriber summary_sub_, rejected_sub_;
  std::mutex mutex_;
  std::unordered_map<std::string, ros::WallTime> sent_at_;
  std::vector<ros::Subscriber> count_subs_;
  std::vector<double> latencies_;
  long messages_ = 0, announced_ = 0;
  int received_ = 0, rejected_ = 0, round_ = 0;
  ros::WallTime last_answer_;
};

template <class T>
std::vector<T> param(const ros::NodeHandle& pnh, const std::string& name, std::vector<T> fallback) {
  pnh.getParam(name, fallback);
  return fallback;
}

/// The lab node in namespace target, as its /diagnostics last reported it.
std::map<std::string, std::string> diagnosticsOf(ros::NodeHandle& nh, const std::string& target, double timeout) {
  std::mutex mutex;
  std::map<std::string, std::string> values;
  const std::string name = target + "/lab: lab runs";  // diagnostic_updater drops the leading /
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      collision_lab_ros::kDiagnosticsTopic, 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
        for (const auto& status : msg->status) {
          if (status.name != name) continue;
          std::lock_guard<std::mutex> lock(mutex);
          for (const auto& kv : status.values) values[kv.key] = kv.value;
        }
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (!values.empty()) return values;
    }
    if (!ros::ok() || ros::WallTime::now() > end) return {};
    ros::WallDuration(0.05).sleep();
  }
}

/// Goal 2 of issue 13: the worker's time per run spent handing a run over to the bag
/// writer, as the recording node reports it in /diagnostics (its newest runs).
void printRecordingGoal(ros::NodeHandle& nh, const std::string& target, const std::vector<TargetResult>& results,
                        const std::vector<std::string>& targets) {
  const auto it = std::find(targets.begin(), targets.end(), target);
  if (it == targets.end()) return;
  const auto values = diagnosticsOf(nh, target, 5.0);
  const auto value = [&](const std::string& key) {
    const auto v = values.find(key);
    return v == values.end() ? -1.0 : std::stod(v->second);
  };
  const double median = value("recording hand-over per run, median [us]");
  const double p99 = value("recording hand-over per run, p99 [us]");
  const double per_run_us = 1e6 / std::max(1.0, results[static_cast<std::size_t>(it - targets.begin())].rate);
  if (median < 0) {
    std::printf("goal: recording, node-thread time per run = unknown (no /diagnostics from %s within 5 s): missed\n",
                target.c_str());
    return;
  }
  std::printf("goal: recording, node-thread hand-over per run (median; p99 %.1f us) = %.1f us against "
              "a whole recorded run end to end = %.1f us (%.3fx; goal <= 100 us): %s\n",
              p99, median, per_run_us, median / per_run_us, median <= 100.0 ? "met" : "missed");
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
  scene.masses = masses;
  scene.positions = positions;
  scene.velocities = velocities;
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
  // Each target's process, for the CPU time it spends per run.
  std::vector<int> pids;
  for (const auto& target : targets) {
    pids.push_back(pidOfPublisher(ros::names::resolve(target + "/" + collision_lab_ros::kRunSummariesTopic)));
  }
  std::vector<std::vector<TargetResult>> rounds_of(targets.size());
  std::vector<std::vector<double>> cpu_us_of(targets.size());  // per round [us per run]
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t t = 0; t < targets.size(); ++t) {
      ROS_INFO_STREAM("round " << round + 1 << "/" << rounds << ": " << targets[t] << ", " << runs << " runs");
      const double cpu_before = processCpuSeconds(pids[t]);
      rounds_of[t].push_back(clients[t]->run(scene, runs, timeout));
      cpu_us_of[t].push_back(1e6 * (processCpuSeconds(pids[t]) - cpu_before) / runs);
    }
  }
  // Per target and round: its rate over the relay's in the same round (the relay is
  // measured right before it, under the same load); the goal is the median of these.
  std::vector<std::vector<double>> ratios_of(targets.size());
  for (std::size_t t = 0; t < targets.size(); ++t) {
    for (int round = 0; round < rounds; ++round) {
      const double relay = rounds_of.front()[round].rate;
      ratios_of[t].push_back(relay > 0 ? rounds_of[t][round].rate / relay : 0.0);
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
    median_round.messages = median_round.announced = 0;
    for (const auto& r : all) {
      p50.push_back(r.p50_ms);
      p99.push_back(r.p99_ms);
      median_round.sent += r.sent;
      median_round.received += r.received;
      median_round.rejected += r.rejected;
      median_round.messages += r.messages;
      median_round.announced += r.announced;
    }
    median_round.p50_ms = percentile(p50, 0.5);
    median_round.p99_ms = percentile(p99, 0.5);
    results.push_back(median_round);
  }

  const double relay_rate = results.front().rate;
  std::printf("\nNode throughput over loopback: %d rounds of %d runs per target (medians over rounds; 'vs relay' is "
              "the median of the per-round ratios to the relay), scene of %zu bodies, mode %d; every per-run topic "
              "subscribed\n",
              rounds, runs, masses.size(), scene.mode);
  std::printf("%-12s %8s %9s %6s %10s %10s %10s %10s %9s  %s\n", "target", "sent", "answered", "lost", "msgs/run",
              "runs/s", "p50 [ms]", "p99 [ms]", "vs relay", "per round [%]");
  for (std::size_t t = 0; t < results.size(); ++t) {
    const TargetResult& r = results[t];
    const long lost = (r.sent - r.received - r.rejected) + (r.announced - r.messages);
    std::printf("%-12s %8d %9d %6ld %10.1f %10.0f %10.2f %10.2f %8.0f%%  %s\n", r.target.c_str(), r.sent, r.received,
                lost, r.received ? double(r.messages) / r.received : 0.0, r.rate, r.p50_ms, r.p99_ms,
                100 * median(ratios_of[t]), percentList(ratios_of[t]).c_str());
  }
  const std::string compute_target = pnh.param<std::string>("compute_target", "norecord");
  for (std::size_t t = 0; t < results.size(); ++t) {
    const TargetResult& r = results[t];
    if (r.target != compute_target) continue;
    const double ratio = median(ratios_of[t]);
    const bool lossless = r.sent == r.received && r.messages == r.announced;
    std::printf("goal: lab node compute path ('%s', recording off), runs/s = %.0f against relay publishing the same "
                "messages = %.0f (median rates; median of the %d per-round ratios, each round measuring both: %.0f%%, "
                "rounds %s%%; goal >= 80%%, nothing lost): %s\n",
                r.target.c_str(), r.rate, relay_rate, rounds, 100 * ratio, percentList(ratios_of[t]).c_str(),
                ratio >= 0.8 && lossless ? "met" : "missed");
    if (!(ratio >= 0.8 && lossless) && pids.front() > 0 && pids[t] > 0) {
      const double node_cpu = median(cpu_us_of[t]), relay_cpu = median(cpu_us_of.front());
      std::printf("why: CPU time per run, all threads, median of the %d rounds: the lab node %.1f us, the relay %.1f "
                  "us (%.2fx); the node computes each run (validation, model, simulation, conversion) where the relay "
                  "only copies; both share the 2 cores with this client and the other targets\n",
                  rounds, node_cpu, relay_cpu, relay_cpu > 0 ? node_cpu / relay_cpu : 0.0);
    }
  }
  const std::string recording_target = pnh.param<std::string>("recording_target", "record");
  printRecordingGoal(nh, recording_target, results, targets);
  spinner.stop();
  return 0;
}
