// collision_lab_web: the class's web server beside collision_lab_node (docs/web.md).
// Sends scenes as InitialConditions on the lab node's `initial_conditions` and follows its
// topics, so a browser's run is recorded, published and drawn like any other.
#include <arpa/inet.h>
#include <ifaddrs.h>
#include <malloc.h>
#include <netinet/in.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <ros/package.h>
#include <ros/ros.h>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/Cancel.h"
#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunQueue.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_recorder.h"
#include "collision_lab/service/run_index.h"
#include "collision_lab/web/run_book.h"
#include "collision_lab/web/web_server.h"

namespace {

/// [s] between two returns of freed memory to the system.
constexpr double kFreedMemoryPeriod = 5.0;

using namespace collision_lab_ros;  // topic names and queue sizes
using collision_lab_web::WebConfig;

/// A non-negative integer parameter (XmlRpc has only int).
std::size_t sizeParam(const ros::NodeHandle& pnh, const std::string& name, std::size_t fallback) {
  int value = static_cast<int>(fallback);
  pnh.param(name, value, value);
  return static_cast<std::size_t>(std::max(1, value));
}

std::string defaultBagDirectory();

WebConfig loadConfig(const ros::NodeHandle& pnh) {
  WebConfig c;
  const std::string package = ros::package::getPath("collision_lab");
  pnh.param("bind", c.bind, c.bind);
  pnh.param("port", c.port, c.port);
  pnh.param("code", c.code, c.code);
  pnh.param("teacher_code", c.teacher_code, c.teacher_code);
  pnh.param("allowed_hosts", c.allowed_hosts, c.allowed_hosts);
  c.max_body_bytes = sizeParam(pnh, "max_body_bytes", c.max_body_bytes);
  c.max_bodies = sizeParam(pnh, "max_bodies", c.max_bodies);
  c.runs_per_minute = sizeParam(pnh, "runs_per_minute", c.runs_per_minute);
  c.runs_per_minute_per_address = sizeParam(pnh, "runs_per_minute_per_address", c.runs_per_minute_per_address);
  c.runs_per_hour = sizeParam(pnh, "runs_per_hour", c.runs_per_hour);
  int unfinished = static_cast<int>(c.unfinished_runs_per_address);
  pnh.param("unfinished_runs_per_address", unfinished, unfinished);
  c.unfinished_runs_per_address = static_cast<std::size_t>(std::max(0, unfinished));  // 0: no cap
  c.max_streams = sizeParam(pnh, "max_streams", c.max_streams);
  c.code_attempts = sizeParam(pnh, "code_attempts", c.code_attempts);
  c.code_attempts_total = sizeParam(pnh, "code_attempts_total", c.code_attempts_total);
  c.max_streams_per_address = sizeParam(pnh, "max_streams_per_address", c.max_streams_per_address);
  pnh.param("code_lockout", c.code_lockout, c.code_lockout);
  pnh.param("answer_timeout", c.answer_timeout, c.answer_timeout);
  c.io_threads = sizeParam(pnh, "io_threads", c.io_threads);
  pnh.param("header_timeout", c.header_timeout, c.header_timeout);
  pnh.param("body_timeout", c.body_timeout, c.body_timeout);
  pnh.param("idle_timeout", c.idle_timeout, c.idle_timeout);
  c.max_connections_per_address = sizeParam(pnh, "max_connections_per_address", c.max_connections_per_address);
  c.max_connections = sizeParam(pnh, "max_connections", c.max_connections);
  pnh.param("web_root", c.web_root, package + "/web");
  pnh.param("chartjs_path", c.chartjs_path, std::string("/usr/share/javascript/chart.js/chart.min.js"));
  pnh.param("scenario_file", c.scenario_file, package + "/" + kDefaultScenarioFile);
  pnh.param("bag_directory", c.state_directory, defaultBagDirectory());
  c.state_directory = expandUser(c.state_directory);
  return c;
}

/// The lab node's bag folder when it is given none (as the lab node computes it, for the
/// same namespace): $ROS_HOME/collision_lab/runs followed by the namespace.
std::string defaultBagDirectory() {
  const char* ros_home = std::getenv("ROS_HOME");
  const std::string base = ros_home && *ros_home ? ros_home : expandUser("~/.ros");
  const std::string& ns = ros::this_node::getNamespace();
  return base + "/" + kDefaultBagSubdirectory + (ns == "/" ? std::string() : ns);
}

/// The RunBook's budget and its run index (docs/web.md, "Memory and restarts"): ~memory_budget_bytes
/// [bytes], ~reconcile_period [s], ~run_index (default <~bag_directory>/runs.sqlite; empty:
/// none). Without a readable index the book keeps stubs of evicted runs and says so.
std::unique_ptr<collision_lab_web::RunBook> makeRunBook(const ros::NodeHandle& pnh) {
  collision_lab_web::RunBookOptions options;
  int budget = static_cast<int>(options.memory_budget_bytes);
  double period = 2.0;
  pnh.param("memory_budget_bytes", budget, budget);
  pnh.param("reconcile_period", period, period);
  options.memory_budget_bytes = static_cast<std::size_t>(std::max(1, budget));
  options.reconcile_period = std::chrono::milliseconds(static_cast<long>(std::max(0.1, period) * 1000.0));
  options.reconcile_after = options.reconcile_period;
  std::string bag_directory, index_path;
  pnh.param("bag_directory", bag_directory, defaultBagDirectory());
  bag_directory = expandUser(bag_directory);
  pnh.param("run_index", index_path, collision_lab::service::RunIndex::defaultPath(bag_directory));
  std::shared_ptr<const collision_lab_web::RunSource> source;
  if (!index_path.empty()) {
    try {
      std::error_code ignored;
      std::filesystem::create_directories(std::filesystem::path(index_path).parent_path(), ignored);
      source = collision_lab_web::openIndexRunSource(index_path);
      ROS_INFO_STREAM("Run index: " << index_path << " (runs of earlier sessions are listed and served)");
    } catch (const std::exception& e) {
      ROS_WARN_STREAM("No run index (" << e.what() << "): only the runs seen since this start are listed");
    }
  }
  return std::make_unique<collision_lab_web::RunBook>(options, source);
}

/// The addresses to give the class: the bound one, or every IPv4 address of the machine
/// when bound to all (0.0.0.0).
std::vector<std::string> addresses(const std::string& bind) {
  if (bind != "0.0.0.0") return {bind};
  std::vector<std::string> out;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return {bind};
  for (ifaddrs* a = list; a; a = a->ifa_next) {
    if (!a->ifa_addr || a->ifa_addr->sa_family != AF_INET) continue;
    char text[INET_ADDRSTRLEN];
    inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(a->ifa_addr)->sin_addr, text, sizeof text);
    out.emplace_back(text);
  }
  freeifaddrs(list);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_web");
  ros::NodeHandle nh, pnh("~");
  const WebConfig config = loadConfig(pnh);
  const std::unique_ptr<collision_lab_web::RunBook> book_owner = makeRunBook(pnh);
  collision_lab_web::RunBook& book = *book_owner;
  // Runs are taken (not 503) once the lab node subscribes: said in the log, for the teacher.
  ros::Publisher inputs = nh.advertise<collision_lab::InitialConditions>(
      kInitialConditionsTopic, kInputQueueSize,
      [](const ros::SingleSubscriberPublisher& p) { ROS_INFO_STREAM("Class page ready: " << p.getSubscriberName() << " takes the runs"); },
      [](const ros::SingleSubscriberPublisher& p) {
        ROS_WARN_STREAM("collision_lab_web: " << p.getSubscriberName() << " no longer takes runs; a POST gets 503 until a lab node is back");
      });
  // Sized as the lab node's outputs (node_constants.h): a run's burst of events is never dropped.
  std::vector<ros::Subscriber> subs = {
      nh.subscribe(kAcceptedRunsTopic, kOutputQueueSize, &collision_lab_web::RunBook::onAccepted, &book),
      nh.subscribe(kRejectedTopic, kOutputQueueSize, &collision_lab_web::RunBook::onRejected, &book),
      nh.subscribe(kServedInputsTopic, kOutputQueueSize, &collision_lab_web::RunBook::onServedInput, &book),
      nh.subscribe(kPredictionsTopic, kOutputQueueSize, &collision_lab_web::RunBook::onPrediction, &book),
      nh.subscribe(kCollisionEventsTopic, kOutputQueueSize, &collision_lab_web::RunBook::onEvent, &book),
      nh.subscribe(kRunProgressTopic, kOutputQueueSize, &collision_lab_web::RunBook::onProgress, &book),
      nh.subscribe(kRunSummariesTopic, kOutputQueueSize, &collision_lab_web::RunBook::onSummary, &book)};
  auto publish = [&inputs](const collision_lab::InitialConditions& input) {
    if (inputs.getNumSubscribers() == 0) return false;
    collision_lab::InitialConditions stamped = input;
    stamped.header.stamp = ros::Time::now();
    inputs.publish(stamped);
    return true;
  };
  // The lab node's ~cancel, by its name (~lab_node, resolved in this node's namespace).
  std::string lab_node;
  pnh.param("lab_node", lab_node, std::string("collision_lab_node"));
  const std::string cancel_service = ros::names::resolve(lab_node) + "/" + kCancelService;
  auto cancel = [cancel_service](const std::string& run_id,
                                 const std::string& requested_by) -> std::optional<collision_lab_web::CancelAnswer> {
    collision_lab::Cancel call;
    call.request.run_id = run_id;
    call.request.requested_by = requested_by;
    if (!ros::service::waitForService(cancel_service, ros::Duration(2.0)) || !ros::service::call(cancel_service, call)) {
      return std::nullopt;
    }
    return collision_lab_web::CancelAnswer{call.response.ok != 0, call.response.message};
  };
  auto log = [](const std::string& line) { ROS_WARN_STREAM("collision_lab_web: " << line); };
  try {
    collision_lab_web::WebServer server(book, config, publish, cancel, log);
    // The lab node's queue (latched, published when it changes; topic new in 0.7.0).
    ros::Subscriber queue = nh.subscribe<collision_lab::RunQueue>(
        "run_queue", 1, [&server](const collision_lab::RunQueue::ConstPtr& msg) { server.setQueue(*msg); });
    server.start();
    std::string urls;
    for (const auto& a : addresses(config.bind)) {
      const std::string url = "http://" + a + ":" + std::to_string(server.port()) + "/";
      urls += (urls.empty() ? "" : " ") + url;
    }
    pnh.setParam("url", "http://" + (config.bind == "0.0.0.0" ? std::string("127.0.0.1") : config.bind) + ":" +
                            std::to_string(server.port()) + "/");
    ROS_INFO_STREAM("Class page: " << urls << (config.bind == "127.0.0.1" ? " (this machine only; web_bind:=0.0.0.0 opens it to the lab's network)" : " (give this address to the class)")
                                   << (config.code.empty() ? "" : "; every page needs the class code")
                                   << (config.teacher_code.empty() ? "" : "; the teacher page needs the teacher code"));
    // The memory the node's threads freed (requests answered, runs evicted or read back)
    // goes back to the system every few seconds: glibc keeps it in each thread's arena
    // otherwise, and the node's resident memory would be its busiest moment's.
    ros::WallTimer give_back = nh.createWallTimer(ros::WallDuration(kFreedMemoryPeriod),
                                                  [](const ros::WallTimerEvent&) { malloc_trim(0); });
    ros::AsyncSpinner spinner(1);
    spinner.start();
    ros::waitForShutdown();
    server.stop();
  } catch (const std::exception& e) {
    ROS_FATAL_STREAM("collision_lab_web: " << e.what());
    return 1;
  }
  return 0;
}
