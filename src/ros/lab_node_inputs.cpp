// The lab node's inputs: the topic initial_conditions and the services ~run_scene,
// ~run_preset, ~list_runs and ~cancel.
#include <future>
#include <sstream>

#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/lab_node.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_index_recorder.h"
#include "lab_node_shared.h"

namespace collision_lab_ros {
namespace {

/// Fills a RunScene or RunPreset response (their fields are the same).
template <class Response>
void fillResponse(const std::optional<ServeOutcome>& outcome, Response& response) {
  if (!outcome) {
    response.ok = false;
    response.message = "collision_lab_node is shutting down; the input was not served";
    return;
  }
  response.ok = outcome->summary.has_value();
  if (!response.ok) {
    const collision_lab::Rejected& r = outcome->rejected;
    response.rejected = r;
    response.message = "rejected run '" + r.run_id + "': " + r.reason_name + " in " + r.field +
                       ": " + r.message;
    return;
  }
  const collision_lab::RunSummary& s = *outcome->summary;
  response.summary = s;
  std::ostringstream line;
  line << "run " << s.run_id << ": " << s.collision_count << " collisions, " << predictedText(s);
  if (s.truncated) line << " (truncated: " << s.truncation_reason << ")";
  if (!s.requested_run_id.empty()) line << "; run_id '" << s.requested_run_id << "' was taken";
  if (s.bag_path.empty()) {
    line << "; not recorded";
  } else if (s.recording_ok) {
    line << "; bag " << s.bag_path;
  } else {
    line << "; recording FAILED: " << s.recording_error;
  }
  response.message = line.str();
}

}  // namespace

void LabNode::onInitialConditions(const collision_lab::InitialConditions::ConstPtr& msg) { intake(*msg, nullptr); }

std::optional<ServeOutcome> LabNode::serveAndWait(const collision_lab::InitialConditions& input) {
  auto reply = std::make_shared<std::promise<ServeOutcome>>();
  std::future<ServeOutcome> outcome = reply->get_future();
  intake(input, std::move(reply));
  try {
    return outcome.get();
  } catch (const std::future_error&) {
    return std::nullopt;  // dropped: the node is shutting down
  }
}

bool LabNode::onRunScene(collision_lab::RunScene::Request& request,
                         collision_lab::RunScene::Response& response) {
  collision_lab::InitialConditions input;
  input.run_id = request.run_id;
  input.student = request.student;
  input.mode = request.mode;
  input.masses = request.masses;
  input.positions = request.positions;
  input.velocities = request.velocities;
  input.restitution = request.restitution;
  input.max_collisions = request.max_collisions;
  input.max_run_seconds = request.max_run_seconds;
  input.max_bag_bytes = request.max_bag_bytes;
  fillResponse(serveAndWait(input), response);
  return true;
}

bool LabNode::onRunPreset(collision_lab::RunPreset::Request& request,
                          collision_lab::RunPreset::Response& response) {
  collision_lab::io::SceneEntry preset;
  try {
    // Read on every call, so that an edited file counts at once.
    preset = collision_lab::io::findScene(collision_lab::io::loadScenes(params_.scenario_file), request.name);
  } catch (const collision_lab::io::ScenarioFileError& e) {
    response.ok = false;
    response.message = e.what();
    return true;
  }
  collision_lab::InitialConditions input =
      toInitialConditions(preset.scene, collision_lab::core::RunMode::kFull, preset.max_collisions);
  input.mode = request.mode;
  input.student = request.student;
  input.run_id =
      request.run_id.empty() ? preset.name + "_" + utcStamp("%Y%m%dT%H%M%SZ") : request.run_id;
  fillResponse(serveAndWait(input), response);
  return true;
}

bool LabNode::onListRuns(collision_lab::ListRuns::Request& request, collision_lab::ListRuns::Response& response) {
  // The index lists every run of bag_directory, across restarts; without it, this process's.
  response.runs = run_index_->ok() ? run_index_->list(request.student) : served_runs_.list(request.student);
  return true;
}

bool LabNode::onCancel(collision_lab::Cancel::Request& request, collision_lab::Cancel::Response& response) {
  // Whoever asks is logged and goes into a summary: bounded, like every name.
  const std::string by = request.requested_by.empty() ? std::string("~cancel") : request.requested_by.substr(0, kMaxStudentLength);
  std::optional<Pool::Entry> waiting;
  {
    const auto lock = pool_->lock();
    if (!request.run_id.empty()) waiting = pool_->remove(request.run_id);
    if (waiting) {
      response.ok = true;
      response.message = "run '" + request.run_id + "' was waiting; cancelled before it started";
    } else {
      const std::vector<std::string> stopped = pool_->stopRunning(request.run_id, StopCause::kCancel, by);
      response.ok = !stopped.empty();
      if (stopped.empty()) {
        response.message = request.run_id.empty() ? "no run in progress"
                                                   : "no run '" + request.run_id + "' is waiting or in progress; nothing stopped";
      } else {
        response.message = "run";
        for (std::size_t i = 0; i < stopped.size(); ++i) response.message += (i ? ", '" : " '") + stopped[i] + "'";
        response.message += " asked to stop";
      }
    }
  }
  if (waiting) dropWaiting(std::move(waiting->job), by);
  ROS_INFO_STREAM("~cancel (by " << by << "): " << response.message);
  return true;
}

}  // namespace collision_lab_ros
