// The lab node's run lifecycle, on a worker: the prediction first, every collision as the
// core reports it, the summary last once the bag is closed; a run that throws ends
// WORKER_ERROR, and a run cancelled while waiting ends with its bag all the same.
#include <filesystem>
#include <string>

#include "collision_lab/ros/lab_node.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/run_index_recorder.h"
#include "collision_lab/ros/run_recorder.h"
#include "collision_lab/ros/run_timeline.h"
#include "lab_node_shared.h"
#include "run_writer.h"

namespace collision_lab_ros {
namespace {

/// At INFO for a lab, at DEBUG with ~log_runs false: at thousands of runs per second an
/// INFO line per run (console, log file and /rosout, another process) costs more than the
/// run itself. Every result is on run_summaries either way, and failures and warnings are
/// still logged as such.
void logRun(const collision_lab::RunSummary& summary, bool at_info) {
  const auto level = at_info ? ::ros::console::levels::Info : ::ros::console::levels::Debug;
  ROS_LOG_STREAM(level, ROSCONSOLE_DEFAULT_NAME,
                 "run " << summary.run_id << ": " << summary.collision_count << " collisions"
                        << (summary.truncated ? " (truncated)" : "") << ", " << predictedText(summary) << ", "
                        << summary.compute_time << " s"
                        << (summary.bag_path.empty() ? std::string() : ", bag " + summary.bag_path));
}

/// The settings a run is served with, under its limits (run_id and stamp are the RunWriter's).
collision_lab::RunParameters runParameters(const LabNodeParams& params, const collision_lab::service::RunLimits& limits) {
  collision_lab::RunParameters msg;
  msg.package_version = COLLISION_LAB_VERSION;
  msg.node_name = ros::this_node::getName();
  msg.max_collisions = limits.max_collisions;
  msg.max_published_events = params.max_published_events;
  msg.max_bodies = params.max_bodies;
  msg.max_run_seconds = limits.max_run_seconds;
  msg.max_bag_bytes = limits.max_bag_bytes;
  return msg;
}

}  // namespace

void LabNode::serve(Worker& worker, Job& job) {
  const ros::Time start = stampNow();
  RunWriter out(job.input.run_id, RunTimeline(start, chooseTimelineScale(firstContactTime(job.plan.scene))),
                worker.slot.bags.get(), job.claim_error,
                RunWriter::RecordLimits{job.limits.max_bag_bytes, admission_.get(), student_quota_.get(),
                                        job.input.student},
                [this, &worker](RunWriter::Limit limit) {
                  const StopCause cause = limit == RunWriter::Limit::kBagBytes    ? StopCause::kBagLimit
                                          : limit == RunWriter::Limit::kFreeSpace ? StopCause::kDiskSpace
                                                                                  : StopCause::kStudentQuota;
                  const auto lock = pool_->lock();
                  Pool::stopWorker(worker, cause, std::string());
                });
  job.input.header.stamp = start;
  RunSoFar progress;
  std::string what;
  try {
    run(worker, job, out, progress);
    return;
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
    what = "an exception of unknown type";
  }
  if (out.finished()) {
    ROS_ERROR_STREAM("run " << job.input.run_id << ": failed after its summary was handed over: " << what);
    return;
  }
  try {
    failRun(worker, job, out, progress, what);
  } catch (...) {
    ROS_ERROR_STREAM("run " << job.input.run_id << ": the worker failed (" << what
                     << ") and could not report it; the node goes on");
  }
}

void LabNode::run(Worker& worker, Job& job, RunWriter& out, RunSoFar& progress) {
  namespace core = collision_lab::core;
  collision_lab::InitialConditions& input = job.input;
  const core::ScenePlan& plan = job.plan;
  const core::RunMode mode = *toRunMode(input.mode);
  run_index_->started(input.run_id);
  publishStart(worker, out, input, plan);  // the prediction goes out before the simulation starts

  core::SceneRunOptions options = sceneRunOptions(mode, job.limits.max_collisions, params_.simulate_to_cap);
  out.record(runParameters(params_, job.limits));
  options.cancel = &worker.cancel;
  const bool fail = !params_.fail_runs_of_student.empty() && input.student == params_.fail_runs_of_student;
  const PublishLimits limits{params_.max_published_events, params_.progress_period, params_.progress_every_events};
  EventStream events(topics_, out, worker.slot.draws ? marker_view_.get() : nullptr, limits, plan.scene,
                     worker.slot.event_messages, progress, fail);
  core::SceneVisitors visitors;
  visitors.impact = [&events](const core::ImpactRecord& r) { events(r); };
  visitors.collapse = [&events](const core::Collapse& c) { events(c); };  // in order, between the impacts
  const core::SceneRunResult result = core::runScene(plan, options, visitors);

  collision_lab::RunSummary& summary = worker.slot.summary_msg;
  fillRunSummaryMsg(result, plan.scene.size(), mode, summary);
  summary.published_events = progress.published;
  summary.events_not_published = events.cut();
  summary.requested_run_id = job.requested_run_id;
  summary.student = input.student;
  applyStopCause(worker, job, summary);
  publishEnd(out, summary, progress.last_time, std::move(job.reply), worker.slot.draws);
}

void LabNode::applyStopCause(Worker& worker, const Job& job, collision_lab::RunSummary& summary) {
  const StopCause cause = worker.stopCause();
  collision_lab::service::StopContext context;
  if (cause == StopCause::kCancel) {  // the pool's lock only for a cancelled run
    const auto lock = pool_->lock();
    context.stopped_by = worker.current.stopped_by;
  }
  context.student = job.input.student;
  context.asked_max_collisions = job.input.max_collisions;
  context.min_free_space_mb = params_.min_free_space_mb;
  context.max_student_bag_mb = params_.max_student_bag_mb;
  const auto stop =
      collision_lab::service::serviceStop(cause, job.limits,
                                          {summary.stop_reason, summary.truncation_reason, summary.collision_count},
                                          context);
  if (!stop) return;
  summary.stop_reason = stop->stop_reason;
  summary.cancelled = stop->cancelled;
  summary.truncated = true;
  summary.truncation_reason = stop->truncation_reason;
}

namespace {

/// The summary of a run that has not computed (its plan's model and prediction only).
void unsimulatedSummary(const collision_lab::core::ScenePlan& plan, const collision_lab::InitialConditions& input,
                        collision_lab::RunSummary& summary) {
  collision_lab::core::SceneRunResult result;
  result.model = plan.model;
  result.prediction = plan.prediction;
  fillRunSummaryMsg(result, plan.scene.size(), *toRunMode(input.mode), summary);
  summary.student = input.student;
}

}  // namespace

void LabNode::failRun(Worker& worker, Job& job, RunWriter& out, const RunSoFar& progress, const std::string& what) {
  ROS_ERROR_STREAM("run " << job.input.run_id << ": the worker failed after " << progress.collisions
                   << " collisions: " << what << "; the run ends WORKER_ERROR and the node goes on");
  collision_lab::RunSummary& summary = worker.slot.summary_msg;
  unsimulatedSummary(job.plan, job.input, summary);
  summary.simulated = true;
  summary.collision_count = progress.collisions;
  summary.published_events = progress.published;
  summary.events_not_published = progress.published < progress.collisions;
  summary.truncated = true;
  summary.stop_reason = "WORKER_ERROR";
  summary.truncation_reason = "the worker failed after " + std::to_string(progress.collisions) +
                              " collisions: " + what + "; the bag holds the collisions before";
  summary.requested_run_id = job.requested_run_id;
  publishEnd(out, summary, progress.last_time, std::move(job.reply), worker.slot.draws);
}

void LabNode::dropWaiting(Job job, const std::string& by) {
  const ros::Time start = stampNow();
  RunWriter out(job.input.run_id, RunTimeline(start, chooseTimelineScale(firstContactTime(job.plan.scene))),
                dropped_bags_.get(), job.claim_error, RunWriter::RecordLimits{}, {});
  job.input.header.stamp = start;
  out.record(job.input);
  out.record(runParameters(params_, job.limits));
  // As every run: its prediction, then its summary; every bag holds parameters, input,
  // prediction and summary.
  collision_lab::Prediction prediction;
  fillPredictionMsg(job.plan, prediction);
  prediction.timeline_scale = out.timeline().scale();
  out.publish(topics_.predictions, prediction, 0.0);
  out.record(prediction);
  collision_lab::RunSummary summary;
  unsimulatedSummary(job.plan, job.input, summary);
  summary.collision_count = 0;
  summary.cancelled = true;
  summary.truncated = true;
  summary.stop_reason = "CANCELLED";
  summary.truncation_reason = "cancelled by " + by + " before it started";
  summary.requested_run_id = job.requested_run_id;
  publishEnd(out, summary, 0.0, std::move(job.reply), false);
}

void LabNode::publishStart(Worker& worker, RunWriter& out, const collision_lab::InitialConditions& input,
                           const collision_lab::core::ScenePlan& plan) {
  out.record(input);
  served_inputs_pub_.publish(input);
  RunObserver* view = worker.slot.draws ? marker_view_.get() : nullptr;
  if (view) view->onInitialConditions(input);
  collision_lab::Prediction& prediction = worker.slot.prediction_msg;
  fillPredictionMsg(plan, prediction);
  prediction.timeline_scale = out.timeline().scale();
  out.publish(topics_.predictions, prediction, 0.0);
  out.record(prediction);
  if (view) view->onPrediction(prediction);
}

void LabNode::publishEnd(RunWriter& out, collision_lab::RunSummary& summary, double last_event_time, Reply reply,
                         bool draws) {
  summary.timeline_scale = out.timeline().scale();
  out.stamp(summary, last_event_time);
  summary.timeline_saturated = out.timeline().saturated();
  if (summary.timeline_saturated) {
    ROS_WARN_STREAM("run " << summary.run_id << ": collisions after " << RunTimeline::kMaxOffset
                    << " bag s are stamped at that limit (timeline_scale "
                    << summary.timeline_scale << ")");
  }
  if (!out.recording()) {
    out.markFinished();
    finishRun(summary, reply, draws);
    return;
  }
  out.finish(summary, [this, reply, draws, counted = out.quotaBytes()](collision_lab::RunSummary& closed) {
    std::error_code ec;
    const auto bag_bytes = std::filesystem::file_size(closed.recording_ok ? closed.bag_path : closed.bag_path + ".active", ec);
    student_quota_->ended(closed.student, counted, ec ? 0 : bag_bytes);
    finishRun(closed, reply, draws);
  });
  recording_times_.add(out.recordingSeconds());
}

void LabNode::finishRun(const collision_lab::RunSummary& summary, const Reply& reply, bool draws) {
  if (params_.record) {
    std::lock_guard<std::mutex> lock(recording_mutex_);
    last_recording_error_ = summary.recording_error;
    if (!summary.recording_ok) ROS_ERROR_STREAM("run " << summary.run_id << ": recording failed: " << summary.recording_error);
  }
  // The summary goes out last, after everything it counts (and its bag is closed).
  served_runs_.finished(summary);  // before the summary: whoever saw it finds the run finished
  run_index_->finished(summary);
  topics_.summaries.publish(summary);
  ++runs_accepted_;
  last_compute_time_ = summary.compute_time;
  if (draws && marker_view_) marker_view_->onRunSummary(summary);
  logRun(summary, params_.log_runs);
  if (reply) reply->set_value(ServeOutcome{summary, {}});
}

}  // namespace collision_lab_ros
