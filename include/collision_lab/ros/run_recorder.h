// One bag per run, written with the rosbag C++ API.
//
// The bag is written as <directory>/<run_id>.bag.active and renamed to <run_id>.bag when
// it is closed, so a finished run's bag is always complete, and the bag of a run cut
// short by a crash is left as .bag.active (recoverable with `rosbag reindex`).
// Recording never throws: a failure is kept in error() and later writes are skipped.
//
// Several writers (nodes, processes) may share one directory. A run's file is claimed
// before the run starts (claimBag): the .bag.active file is created with O_CREAT|O_EXCL,
// so exactly one claimer gets it, and a name whose finished .bag exists is given up
// again. The owner then opens that file with rosbag (Write truncates and writes the
// existing, empty file) and renames it on close with a rename that never replaces a
// file (RENAME_NOREPLACE, or link + unlink where the file system lacks it); if the final
// name exists anyway (a writer that does not claim), the run fails loudly (ok() false)
// and its bag stays .bag.active. So a writer only ever writes and renames a file it
// created itself, and reports success only for that file.
//
// RunBagWriter writes those bags on a thread of its own, so that a run's publisher only
// hands its messages over (see its contract below).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/make_shared.hpp>
#include <ros/time.h>
#include <rosbag/bag.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/RunParameters.h"
#include "collision_lab/RunSummary.h"

namespace collision_lab_ros {

/// A claim's file before it takes the .active name: <run_id>.bag.active<kClaimInfix><pid>.<n>
/// (left only by a claimer that died in between; recoverActiveBags removes it).
constexpr char kClaimInfix[] = ".claim.";

/// <directory>/<run_id>.bag
std::string bagPath(const std::string& directory, const std::string& run_id);

enum class BagClaim {
  kClaimed,  ///< the caller created <run_id>.bag.active and owns it
  kTaken,    ///< <run_id>.bag or <run_id>.bag.active exists (whoever made it); nothing was created
  kFailed,   ///< the directory or the file could not be created; error says why
};

/// Claims <directory>/<run_id>.bag for the caller, race-free against every process that
/// claims in directory this way: creates directory if needed, creates <run_id>.bag.active
/// exclusively (kTaken when it exists), then gives the name up again (removes the file it
/// just created: kTaken) when a finished <run_id>.bag exists. A finished bag only appears
/// by its owner's rename of the .active file, which the exclusive create excludes until
/// then, so after kClaimed no other claimer can get this run_id.
/// Ownership: on kClaimed this process holds flock(LOCK_EX) on the .active file (from
/// the moment the name exists: it is made locked under a private name, then renamed)
/// until releaseBagClaim, which RunRecorder calls once the bag is closed or has failed.
/// The kernel drops the lock when the process dies, so an .active file that
/// flock(LOCK_EX|LOCK_NB) can take has no live owner (recoverActiveBags).
BagClaim claimBag(const std::string& directory, const std::string& run_id, std::string& error);
/// Drops this process's claim lock on active_path (<run_id>.bag.active); nothing when it
/// holds none. A claimed run that never opens its bag (e.g. cancelled while queued) must
/// call this, or the lock stays until the process ends.
void releaseBagClaim(const std::string& active_path);
/// Whether this process holds the claim lock on active_path.
bool bagClaimHeld(const std::string& active_path);

/// The connection header a live subscription to topic gives `rosbag record`: topic, type,
/// md5sum, message_definition, callerid (the publishing node) and latching ("1" or "0").
/// `rosbag play` publishes each (callerid, topic) as its own publisher, latched when
/// latching is "1".
template <class Message>
boost::shared_ptr<ros::M_string> connectionHeader(const std::string& topic, const std::string& callerid,
                                                  bool latching) {
  auto header = boost::make_shared<ros::M_string>();
  (*header)["topic"] = topic;
  (*header)["type"] = ros::message_traits::datatype<Message>();
  (*header)["md5sum"] = ros::message_traits::md5sum<Message>();
  (*header)["message_definition"] = ros::message_traits::definition<Message>();
  (*header)["callerid"] = callerid;
  (*header)["latching"] = latching ? "1" : "0";
  return header;
}

/// Expands a leading "~" to $HOME.
std::string expandUser(const std::string& path);

/// Releases bag unless it is closed: a rosbag::Bag that failed to close (RunRecorder's
/// closeIntoNull) would throw from its destructor and end the process, so it is leaked,
/// its file pointed at /dev/null. Logs each leak.
void keepIfClosable(std::unique_ptr<rosbag::Bag>& bag);

class RunRecorder {
 public:
  /// Claims the run's bag (claimBag; a run_id that is taken fails, nothing is
  /// overwritten) and opens it (LZ4-compressed).
  RunRecorder(const std::string& directory, const std::string& run_id);
  /// Opens the bag the caller claimed with claimBag (claim_error empty) in reused, a
  /// closed Bag that outlives this recorder: constructing a rosbag::Bag loads its
  /// encryption plugin (milliseconds), reopening one does not. A non-empty claim_error
  /// is why the claim failed: the recorder fails with it and touches no file.
  RunRecorder(const std::string& directory, const std::string& run_id, rosbag::Bag& reused,
              const std::string& claim_error);
  ~RunRecorder();
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  /// Writes msg on topic at stamp (which must be >= ros::TIME_MIN); with a
  /// connection_header (connectionHeader()) its connection gets that header, as `rosbag
  /// record` writes a live connection's.
  template <class Message>
  void write(const std::string& topic, const ros::Time& stamp, const Message& msg,
             const boost::shared_ptr<ros::M_string>& connection_header = {}) {
    if (!ok()) return;
    try {
      bag_->write(topic, stamp, msg, connection_header);
    } catch (const std::exception& e) {
      fail(std::string("writing ") + topic + " failed: " + e.what());
    }
  }

  /// Closes the bag and gives it its final name, never replacing a file. Returns ok().
  bool close();

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  /// Marks the recording failed, keeping the first error: later writes are skipped and
  /// close() keeps the .active name.
  void fail(const std::string& what);
  /// The final path <directory>/<run_id>.bag.
  const std::string& path() const { return path_; }

 private:
  void open();
  /// Closes a bag whose writes failed (e.g. a full disk): rosbag's close() throws before
  /// it closes such a file, and ~Bag would throw again and end the process. The file's
  /// descriptor is pointed at /dev/null and the bag closed into it: what was written stays
  /// in the .active file for recovery, and deleting that file frees its space.
  void closeIntoNull();

  std::string path_;
  std::string active_path_;
  std::string error_;
  std::unique_ptr<rosbag::Bag> owned_;  ///< null when the bag is reused
  rosbag::Bag* bag_ = nullptr;          ///< the open bag; null once closed or failed
};

/// A part of one run's bag, in recording order: the parameters, the input, the
/// prediction, the events, then the summary. Each message is written at its header.stamp.
struct RunBagBatch {
  std::string run_id;
  bool opens = false;  ///< the run's first batch: its bag (claimed by the caller) is opened first
  /// With opens: empty when the caller claimed the run's bag (claimBag), else why that
  /// failed; the run is then not recorded (recording_ok false, recording_error this).
  std::string claim_error;
  std::optional<collision_lab::RunParameters> parameters;
  std::optional<collision_lab::InitialConditions> input;
  std::optional<collision_lab::Prediction> prediction;
  std::vector<collision_lab::CollisionEvent> events;
  /// The run's last batch: its summary is written with bag_path, recording_ok and
  /// recording_error as they stand before closing, then the bag is closed, and on_closed
  /// gets the summary with the recording fields as they stand after closing.
  std::optional<collision_lab::RunSummary> summary;
  std::function<void(collision_lab::RunSummary&)> on_closed;
  /// [bytes] serialized size of its messages (as the caller counts them), 0 if not counted.
  std::uint64_t bytes = 0;

  std::size_t messages() const { return parameters.has_value() + input.has_value() + prediction.has_value() + events.size() + summary.has_value(); }
};

/// Writes per-run bags (RunRecorder) on its own thread.
/// Contract: the caller claims each run's bag (claimBag) before handing over its first
/// batch, or says in claim_error why it could not. Batches are written in the order handed over, one run at a time (a run's
/// batches are contiguous). push() blocks while more than max_queued_messages messages
/// wait (backpressure: nothing is ever dropped). The destructor writes everything handed
/// over and closes every bag, calling each on_closed, before it returns. on_closed runs
/// on the writer's thread. An exception while writing a batch (on_closed's included) is
/// logged (ROS_ERROR) and ends only that run's recording: its bag stays .bag.active, its
/// on_closed, if not yet called, gets recording_ok false and recording_error saying so,
/// and the writer serves the next runs.
class RunBagWriter {
 public:
  struct Topics {
    std::string inputs, predictions, events, summaries;
    std::string parameters;  ///< of RunBagBatch::parameters; empty: they are not written
    /// The recording node's name, callerid of the latched topics' connections.
    std::string callerid;
    /// Of the topics above, those the node latches: their connection headers get callerid
    /// and latching=1, as `rosbag record` writes them, so that `rosbag play` latches them.
    std::vector<std::string> latched;
  };
  RunBagWriter(std::string directory, Topics topics, std::size_t max_queued_messages);
  ~RunBagWriter();
  RunBagWriter(const RunBagWriter&) = delete;
  RunBagWriter& operator=(const RunBagWriter&) = delete;

  void push(RunBagBatch batch);
  /// [bytes] handed over to every RunBagWriter of this process and not yet written: the
  /// disk space they will take (at most: bags are compressed).
  static std::uint64_t bytesWaiting();

 private:
  void loop();
  void write(RunBagBatch& batch);
  /// After write(batch) threw `what`: see the contract above.
  void recover(RunBagBatch& batch, const std::string& what);
  /// connectionHeader<Message>(topic) for a latched topic; null (rosbag's own) for the others.
  template <class Message>
  boost::shared_ptr<ros::M_string> headerFor(const std::string& topic) const;

  const std::string directory_;
  const Topics topics_;
  const std::size_t max_queued_;
  /// The connection headers of the latched topics (null: not latched), built once.
  const boost::shared_ptr<ros::M_string> parameters_header_, input_header_, prediction_header_, summary_header_;
  /// The writer thread's, reopened for every run and replaced every kBagReuses runs, or
  /// after a bag that could not be closed (keepIfClosable).
  std::unique_ptr<rosbag::Bag> bag_;
  std::size_t bag_reuses_ = 0;
  static constexpr std::size_t kBagReuses = 100;
  std::optional<RunRecorder> recorder_;  ///< the writer thread's: the run being written

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<RunBagBatch> queue_;
  std::size_t queued_messages_ = 0;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace collision_lab_ros
