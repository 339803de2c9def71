#include "collision_lab/ros/run_index_recorder.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <ros/console.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/core/nbody/scene.h"
#include "collision_lab/ros/bag_reading.h"
#include "collision_lab/ros/run_recorder.h"

extern char** environ;

namespace collision_lab_ros {

namespace fs = std::filesystem;
using collision_lab::service::IndexedRejection;
using collision_lab::service::IndexedRun;
using collision_lab::service::RunIndex;
using collision_lab::service::RunIndexError;
using collision_lab::service::RunState;
using nlohmann::json;

namespace {

constexpr char kActiveSuffix[] = ".bag.active";

/// [s] since the epoch, wall time.
double wallNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

/// JSON has no inf or NaN: null.
json finite(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

/// InitialConditions.restitution_model from its name or its number (inputFields).
std::uint8_t restitutionModelOf(const json& j) {
  namespace core = collision_lab::core;
  const json& model = j.contains("restitution_model") ? j["restitution_model"] : json();
  if (model.is_number_unsigned() && model.get<std::uint64_t>() <= 255) return static_cast<std::uint8_t>(model.get<std::uint64_t>());
  for (const auto kind : {core::RestitutionModelKind::kConstant, core::RestitutionModelKind::kTc,
                          core::RestitutionModelKind::kViscoelastic, core::RestitutionModelKind::kThreshold}) {
    if (model.is_string() && model.get<std::string>() == core::restitutionModelName(kind)) {
      return static_cast<std::uint8_t>(kind);
    }
  }
  throw std::invalid_argument("its stored input has no restitution_model");
}

json finiteArray(const std::vector<double>& values) {
  json out = json::array();
  for (double v : values) out.push_back(finite(v));
  return out;
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// A descriptor holding flock(LOCK_EX) on a file, closed (unlocked) on destruction.
class FileLock {
 public:
  /// Opens path and takes its lock without waiting; held() false when another open file
  /// description holds it (a live owner) or path cannot be opened.
  explicit FileLock(const std::string& path) : fd_(::open(path.c_str(), O_RDONLY | O_CLOEXEC)) {
    if (fd_ >= 0 && ::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  ~FileLock() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  bool held() const { return fd_ >= 0; }
  /// Whether path still names the locked file (another recoverer may have renamed or
  /// removed it between our open and our lock).
  bool stillAt(const std::string& path) const {
    struct stat by_fd {}, by_name {};
    return fd_ >= 0 && ::fstat(fd_, &by_fd) == 0 && ::stat(path.c_str(), &by_name) == 0 &&
           by_fd.st_dev == by_name.st_dev && by_fd.st_ino == by_name.st_ino;
  }
  std::uintmax_t size() const {
    struct stat st {};
    return ::fstat(fd_, &st) == 0 ? static_cast<std::uintmax_t>(st.st_size) : 0;
  }

 private:
  int fd_;
};

/// Runs `rosbag reindex -q --output-dir out_dir bag` and waits; empty on success, else why not.
std::string reindexInto(const std::string& bag, const std::string& out_dir) {
  std::vector<std::string> args{"rosbag", "reindex", "-q", "--output-dir", out_dir, bag};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = ::posix_spawnp(&pid, "rosbag", nullptr, nullptr, argv.data(), environ);
  if (spawned != 0) return std::string("cannot run rosbag reindex (python3-rosbag): ") + std::strerror(spawned);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return std::string("waiting for rosbag reindex: ") + std::strerror(errno);
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    return "rosbag reindex failed (status " + std::to_string(status) + ")";
  }
  return {};
}

/// Renames from to to unless to exists. Returns 0 or an errno.
int renameNoReplace(const std::string& from, const std::string& to) {
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS) return errno;
  if (::link(from.c_str(), to.c_str()) != 0) return errno;
  return ::unlink(from.c_str()) == 0 ? 0 : errno;
}

/// Recovers one dead owner's active file (locked by the caller) into final.
RecoveredBag recoverOne(const std::string& directory, const std::string& active, const std::string& run_id,
                        const FileLock& lock) {
  RecoveredBag recovered;
  recovered.run_id = run_id;
  if (lock.size() == 0) {
    // A claim whose bag was never opened: nothing to keep.
    std::error_code ec;
    fs::remove(active, ec);
    if (ec) recovered.error = "cannot remove the empty claim " + active + ": " + ec.message();
    return recovered;
  }
  const std::string final_path = bagPath(directory, run_id);
  // A private folder beside the bags (same file system: the rename below is atomic).
  const std::string work = (fs::path(directory) / (".recovering." + std::to_string(::getpid()))).string();
  std::error_code ec;
  fs::create_directories(work, ec);
  if (ec) {
    recovered.error = "cannot create " + work + ": " + ec.message();
    return recovered;
  }
  const std::string reindexed = (fs::path(work) / fs::path(active).filename()).string();
  std::string error;
  try {
    readBagContents(active);  // indexed already: closed, but never renamed
    fs::copy_file(active, reindexed, fs::copy_options::overwrite_existing);
  } catch (const std::exception&) {
    error = reindexInto(active, work);
  }
  if (error.empty()) {
    try {
      recovered.contents = readBagContents(reindexed);
    } catch (const std::exception& e) {
      error = std::string("the reindexed bag cannot be read: ") + e.what();
    }
  }
  if (error.empty()) {
    const int renamed = renameNoReplace(reindexed, final_path);
    if (renamed == EEXIST) {
      error = final_path + " exists: not overwritten; " + active + " is left as it is";
    } else if (renamed != 0) {
      error = "cannot rename to " + final_path + ": " + std::strerror(renamed);
    }
  }
  if (error.empty()) {
    fs::remove(active, ec);
    recovered.bag_path = final_path;
  }
  recovered.error = error;
  fs::remove_all(work, ec);
  return recovered;
}

/// Runs one write of a group. A failure is logged as `lost` and the group goes on, except a
/// full disk: rethrown, so that the whole group is kept and tried again.
template <class Write>
void writeOrLog(Write&& write, const std::string& lost) {
  try {
    write();
  } catch (const RunIndexError& e) {
    if (e.diskFull()) throw;
    ROS_ERROR_STREAM(lost << ": " << e.what());
  }
}

std::string interruptedJson(const std::string& bag_path, const BagContents& contents, const std::string& note) {
  return json{{"stop_reason", "INTERRUPTED"},
              {"truncated", true},
              {"truncation_reason", note},
              {"collision_count", contents.events},
              {"events_in_bag", contents.events},
              {"last_event_time", contents.last_event_time},
              {"recorded", !bag_path.empty()}}
      .dump();
}

}  // namespace

json inputFields(const collision_lab::InitialConditions& in) {
  json masses = json::array();
  for (double m : in.masses) masses.push_back(std::isinf(m) && m > 0 ? json("inf") : finite(m));
  const auto model = static_cast<collision_lab::core::RestitutionModelKind>(in.restitution_model);
  const std::string model_name = collision_lab::core::restitutionModelName(model);
  return json{{"run_id", in.run_id},
              {"student", in.student},
              {"mode", in.mode},
              {"masses", masses},
              {"positions", finiteArray(in.positions)},
              {"velocities", finiteArray(in.velocities)},
              {"restitution", finiteArray(in.restitution)},
              {"restitution_model", model_name == "unknown" ? json(in.restitution_model) : json(model_name)},
              {"tc", finite(in.tc)},
              {"elastic_below", finite(in.elastic_below)},
              {"viscoelastic_speed", finite(in.viscoelastic_speed)},
              {"ring", finite(in.ring)},
              {"max_collisions", in.max_collisions},
              {"max_run_seconds", finite(in.max_run_seconds)},
              {"max_bag_bytes", in.max_bag_bytes}};
}

std::string inputJson(const collision_lab::InitialConditions& in) { return inputFields(in).dump(); }

collision_lab::InitialConditions inputFromJson(const std::string& text) {
  return inputFromFields(json::parse(text, nullptr, false));  // not JSON: a discarded value, refused
}

collision_lab::InitialConditions inputFromFields(const json& j) {
  if (!j.is_object()) throw std::invalid_argument("its stored input is not a JSON object");
  const auto numbers = [&](const char* key, bool walls) {
    std::vector<double> values;
    if (!j.contains(key) || !j[key].is_array()) throw std::invalid_argument(std::string("its stored input has no ") + key);
    for (const json& v : j[key]) {
      if (walls && v == "inf") {
        values.push_back(std::numeric_limits<double>::infinity());
      } else if (v.is_number()) {
        values.push_back(v.get<double>());
      } else {
        throw std::invalid_argument(std::string("its stored ") + key + " hold a value that is not a number");
      }
    }
    return values;
  };
  // A value stored as null was not finite; these fields are ignored unless their model (or
  // limit) is in use, where the node accepts only finite ones: null reads back as 0 (unset).
  const auto number = [&](const char* key) {
    if (j.contains(key) && j[key].is_null()) return 0.0;
    if (!j.contains(key) || !j[key].is_number()) throw std::invalid_argument(std::string("its stored input has no ") + key);
    return j[key].get<double>();
  };
  const auto whole = [&](const char* key) {
    if (!j.contains(key) || !j[key].is_number_unsigned()) throw std::invalid_argument(std::string("its stored input has no ") + key);
    return j[key].get<std::uint64_t>();
  };
  collision_lab::InitialConditions in;
  in.run_id = j.value("run_id", "");
  in.student = j.value("student", "");
  in.mode = static_cast<std::uint8_t>(whole("mode"));
  in.masses = numbers("masses", true);
  in.positions = numbers("positions", false);
  in.velocities = numbers("velocities", false);
  in.restitution = numbers("restitution", false);
  in.restitution_model = restitutionModelOf(j);
  in.tc = number("tc");
  in.elastic_below = number("elastic_below");
  in.viscoelastic_speed = number("viscoelastic_speed");
  in.ring = number("ring");
  in.max_collisions = whole("max_collisions");
  in.max_run_seconds = number("max_run_seconds");
  in.max_bag_bytes = whole("max_bag_bytes");
  return in;
}

json summaryFields(const collision_lab::RunSummary& s) {
  return {{"run_id", s.run_id},
          {"student", s.student},
          {"requested_run_id", s.requested_run_id},
          {"mode", s.mode},
          {"model", s.model_name},
          {"model_reason", s.model_reason},
          {"body_count", s.body_count},
          {"collision_count", s.collision_count},
          {"simulated", static_cast<bool>(s.simulated)},
          {"truncated", static_cast<bool>(s.truncated)},
          {"truncation_reason", s.truncation_reason},
          {"cancelled", static_cast<bool>(s.cancelled)},
          {"stop_reason", s.stop_reason},
          {"predicted_collision_count",
           s.predicted_collision_count_defined ? json(s.predicted_collision_count) : json(nullptr)},
          {"paper_collision_count",
           s.paper_predicted_collision_count_defined ? json(s.paper_predicted_collision_count) : json(nullptr)},
          {"infinite_collisions", static_cast<bool>(s.infinite_collisions)},
          {"final_velocities", finiteArray(s.final_velocities)},
          {"energy_lost", finite(s.energy_lost)},
          {"collapsed", static_cast<bool>(s.collapsed)},
          {"max_prediction_error", finite(s.max_prediction_error)},
          {"energy_relative_drift", finite(s.energy_relative_drift)},
          {"momentum_relative_drift", finite(s.momentum_relative_drift)},
          {"compute_time", finite(s.compute_time)},
          {"uncertified_values", s.uncertified_values},
          {"time_beyond_range", static_cast<bool>(s.time_beyond_range)},
          {"published_events", s.published_events},
          {"bag_path", s.bag_path},
          {"recorded", s.recording_ok && !s.bag_path.empty()},
          {"recording_error", s.recording_error}};
}

std::string summaryJson(const collision_lab::RunSummary& s) { return summaryFields(s).dump(); }

collision_lab::RunSummary summaryFromFields(const json& fields) {
  collision_lab::RunSummary s;
  const auto text = [&](const char* key, std::string& into) { into = fields.value(key, into); };
  const auto flag = [&](const char* key, std::uint8_t& into) { into = fields.value(key, static_cast<bool>(into)); };
  const auto number = [&](const json& value) {
    return value.is_null() ? std::numeric_limits<double>::quiet_NaN() : value.get<double>();
  };
  const auto real = [&](const char* key, double& into) {
    if (fields.contains(key)) into = number(fields.at(key));
  };
  const auto count = [&](const char* key, auto& into, std::uint8_t* defined = nullptr) {
    if (!fields.contains(key)) return;
    const json& value = fields.at(key);
    if (defined) *defined = !value.is_null();
    if (!value.is_null()) into = value.get<std::remove_reference_t<decltype(into)>>();
  };
  text("run_id", s.run_id);
  text("student", s.student);
  text("requested_run_id", s.requested_run_id);
  count("mode", s.mode);
  text("model", s.model_name);
  text("model_reason", s.model_reason);
  count("body_count", s.body_count);
  count("collision_count", s.collision_count);
  flag("simulated", s.simulated);
  flag("truncated", s.truncated);
  text("truncation_reason", s.truncation_reason);
  flag("cancelled", s.cancelled);
  text("stop_reason", s.stop_reason);
  count("predicted_collision_count", s.predicted_collision_count, &s.predicted_collision_count_defined);
  count("paper_collision_count", s.paper_predicted_collision_count, &s.paper_predicted_collision_count_defined);
  flag("infinite_collisions", s.infinite_collisions);
  if (fields.contains("final_velocities")) {
    for (const json& v : fields.at("final_velocities")) s.final_velocities.push_back(number(v));
  }
  real("energy_lost", s.energy_lost);
  flag("collapsed", s.collapsed);
  real("max_prediction_error", s.max_prediction_error);
  real("energy_relative_drift", s.energy_relative_drift);
  real("momentum_relative_drift", s.momentum_relative_drift);
  real("compute_time", s.compute_time);
  if (fields.contains("uncertified_values")) s.uncertified_values = fields.at("uncertified_values").get<std::vector<std::string>>();
  flag("time_beyond_range", s.time_beyond_range);
  count("published_events", s.published_events);
  text("bag_path", s.bag_path);
  flag("recorded", s.recording_ok);
  text("recording_error", s.recording_error);
  return s;
}

collision_lab::service::RunEnding endingOf(const collision_lab::RunSummary& summary) {
  collision_lab::service::RunEnding ending;
  ending.model_name = summary.model_name;
  ending.simulated = summary.simulated;
  ending.truncated = summary.truncated;
  ending.collapsed = summary.collapsed;
  ending.cancelled = summary.cancelled;
  if (summary.cancelled) ending.cancel_reason = summary.truncation_reason;
  return ending;
}

BagContents readBagContents(const std::string& path) {
  BagContents contents;
  const ReadableBag bag = openBagForReading(path);
  const rosbag::TypeQuery events_query(std::string(ros::message_traits::datatype<collision_lab::CollisionEvent>()));
  rosbag::View events(*bag, events_query);
  contents.events = events.size();
  if (contents.events > 0) {
    // Only the messages at the last stamp are read: the last event is among them.
    rosbag::View last(*bag, events_query, events.getEndTime(), events.getEndTime());
    for (const rosbag::MessageInstance& m : last) {
      if (const auto e = m.instantiate<collision_lab::CollisionEvent>()) contents.last_event_time = e->time;
    }
  }
  rosbag::View rest(*bag, rosbag::TypeQuery(std::vector<std::string>{
                             ros::message_traits::datatype<collision_lab::InitialConditions>(),
                             ros::message_traits::datatype<collision_lab::RunSummary>()}));
  for (const rosbag::MessageInstance& m : rest) {
    if (const auto input = m.instantiate<collision_lab::InitialConditions>()) contents.input = *input;
    if (const auto summary = m.instantiate<collision_lab::RunSummary>()) contents.summary = *summary;
  }
  return contents;
}

bool activeBagOwned(const std::string& active_path) {
  if (!fs::exists(active_path)) return false;
  return !FileLock(active_path).held();
}

std::vector<RecoveredBag> recoverActiveBags(const std::string& directory, ActiveBags which) {
  std::vector<RecoveredBag> recovered;
  std::error_code ec;
  std::vector<std::string> actives, stale_claims;
  for (const auto& entry : fs::directory_iterator(directory, ec)) {
    const std::string name = entry.path().filename().string();
    if (endsWith(name, kActiveSuffix)) actives.push_back(entry.path().string());
    else if (name.find(std::string(kActiveSuffix) + kClaimInfix) != std::string::npos &&
             name.find(std::string(kClaimInfix) + std::to_string(::getpid()) + ".") == std::string::npos) {
      stale_claims.push_back(entry.path().string());  // another process's (this one's may be in the making)
    }
  }
  for (const std::string& claim : stale_claims) {
    FileLock lock(claim);
    if (lock.held() && lock.stillAt(claim)) fs::remove(claim, ec);
  }
  for (const std::string& active : actives) {
    FileLock lock(active);
    if (!lock.held() || !lock.stillAt(active)) continue;  // a live owner's, or another recoverer's
    if (which == ActiveBags::kEmptyClaims && lock.size() != 0) continue;
    const std::string name = fs::path(active).filename().string();
    recovered.push_back(recoverOne(directory, active, name.substr(0, name.size() - std::strlen(kActiveSuffix)), lock));
  }
  return recovered;
}

RunIndexRecorder::RunIndexRecorder(const std::string& bag_directory)
    : bag_directory_(bag_directory), started_at_(wallNow()) {
  std::error_code ec;
  fs::create_directories(bag_directory, ec);
  try {
    index_ = std::make_unique<RunIndex>(RunIndex::defaultPath(bag_directory));
  } catch (const RunIndexError& e) {
    ROS_ERROR_STREAM("the run index is not written (runs are served and recorded in bags as ever): " << e.what());
  }
  if (index_) writer_ = std::thread(&RunIndexRecorder::writerLoop, this);
}

RunIndexRecorder::~RunIndexRecorder() {
  if (!writer_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(writes_mutex_);
    writer_stops_ = true;
  }
  writes_queued_.notify_one();
  writer_.join();  // every queued write committed
}

std::uint64_t RunIndexRecorder::enqueue(std::function<void()> write, bool urgent) {
  std::lock_guard<std::mutex> lock(writes_mutex_);
  if (pending_.empty()) oldest_pending_ = std::chrono::steady_clock::now();
  pending_.push_back(std::move(write));
  if (urgent) {
    ++urgent_;
    writes_queued_.notify_one();
  }
  return ++queued_;
}

bool RunIndexRecorder::waitWritten(std::uint64_t ticket, std::chrono::milliseconds max_wait, bool unless_locked) const {
  std::unique_lock<std::mutex> lock(writes_mutex_);
  if (written_ >= ticket) return true;
  if (unless_locked && locked_out_) return false;
  ++urgent_;  // a writer waits: commit now
  writes_queued_.notify_one();
  const auto done = [&] { return written_ >= ticket; };
  if (max_wait == std::chrono::milliseconds::max()) {
    writes_committed_.wait(lock, done);
    return true;
  }
  return writes_committed_.wait_for(lock, max_wait, done);
}

bool RunIndexRecorder::flush(std::chrono::milliseconds max_wait, bool unless_locked) const {
  std::uint64_t ticket = 0;
  {
    std::lock_guard<std::mutex> lock(writes_mutex_);
    ticket = queued_;
  }
  return waitWritten(ticket, max_wait, unless_locked);
}

bool RunIndexRecorder::commit(const std::vector<std::function<void()>>& group) {
  try {
    if (index_->writeTogether(
            [&group] {
              for (const auto& write : group) write();  // each logs its own failure (writeOrLog)
            },
            kIndexWriterLockWait)) {
      return true;
    }
    ROS_WARN_STREAM_THROTTLE(10, "run index: locked by another program; " << group.size()
                                                                           << " writes wait and are tried again");
    return false;
  } catch (const std::exception& e) {
    const auto* index_error = dynamic_cast<const RunIndexError*>(&e);
    if (index_error && index_error->diskFull()) {  // kept, like a locked index's, until space is freed
      ROS_ERROR_STREAM_THROTTLE(10, "run index: the disk is full; " << group.size()
                                                                    << " writes wait and are tried again: " << e.what());
      return false;
    }
    // The node serves on; the writes are logged as lost.
    ROS_ERROR_STREAM("run index: " << group.size() << " writes were not committed: " << e.what());
    return true;
  }
}

void RunIndexRecorder::writerLoop() {
  std::vector<std::function<void()>> group;
  std::chrono::milliseconds pause{0};  // before the next try of a refused group; 0 after a commit
  std::unique_lock<std::mutex> lock(writes_mutex_);
  for (;;) {
    writes_queued_.wait(lock, [this] { return !pending_.empty() || writer_stops_; });
    if (pending_.empty()) return;
    if (pause.count() > 0) {
      writes_queued_.wait_for(lock, pause, [this] { return writer_stops_; });
    } else {  // deferrable writes alone wait for an urgent one, or for kDeferredWritesDelay
      writes_queued_.wait_until(lock, oldest_pending_ + kDeferredWritesDelay,
                                [this] { return urgent_ > 0 || writer_stops_; });
    }
    group.swap(pending_);
    urgent_ = 0;
    const bool last_try = writer_stops_;
    lock.unlock();
    const bool committed = commit(group);
    lock.lock();
    locked_out_ = !committed;
    if (!committed && !last_try) {  // kept, in order, ahead of what came meanwhile
      group.insert(group.end(), std::make_move_iterator(pending_.begin()), std::make_move_iterator(pending_.end()));
      pending_.swap(group);
      group.clear();
      pause = std::clamp(2 * pause, std::chrono::milliseconds(250), kIndexRetryMaxPause);
      continue;
    }
    if (!committed) ROS_ERROR_STREAM("run index: " << group.size() << " writes are lost: the node stops and the index is locked or its disk full");
    pause = std::chrono::milliseconds(0);
    written_ += group.size();
    group.clear();
    writes_committed_.notify_all();
  }
}

void RunIndexRecorder::accepted(const std::string& run_id, const std::string& student, const std::string& requested_run_id,
                                const collision_lab::InitialConditions& input) {
  if (!index_) return;
  IndexedRun row;
  row.run_id = run_id;
  row.student = student;
  row.requested_run_id = requested_run_id;
  row.state = RunState::kQueued;
  row.accepted_at = wallNow();
  row.body_count = static_cast<std::uint32_t>(input.masses.size());
  row.scene_json = inputJson(input);
  enqueue(
      [this, row = std::move(row)] {
        writeOrLog([&] { index_->accepted(row); }, "run " + row.run_id + ": not in the run index");
      },
      /*urgent=*/true);
}

void RunIndexRecorder::started(const std::string& run_id) {
  if (!index_) return;
  enqueue(
      [this, run_id, at = wallNow()] {
        writeOrLog([&] { index_->started(run_id, at); }, "run " + run_id + ": its start is not in the run index");
      },
      /*urgent=*/false);
}

void RunIndexRecorder::finished(const collision_lab::RunSummary& summary) {
  if (!index_) return;
  const std::uint64_t ticket =
      enqueue([this, run_id = summary.run_id, at = wallNow(), json = summaryJson(summary),
               stop_reason = summary.stop_reason, count = summary.collision_count,
               bag = summary.recording_ok ? summary.bag_path : std::string(), ending = endingOf(summary)] {
        writeOrLog([&] { index_->finished(run_id, at, json, stop_reason, count, bag, ending); },
                   "run " + run_id + ": its end is not in the run index");
      },
      /*urgent=*/true);
  if (!waitWritten(ticket, kIndexCommitWait, /*unless_locked=*/true)) {
    ROS_WARN_STREAM("run " << summary.run_id << ": its end waits to be written into the run index");
  }
}

void RunIndexRecorder::rejected(const collision_lab::Rejected& rejected) {
  if (!index_) return;
  IndexedRejection row;
  row.at = rejected.header.stamp.isZero() ? wallNow() : rejected.header.stamp.toSec();
  row.student = rejected.student;
  row.run_id = rejected.run_id;
  row.reason_name = rejected.reason_name;
  row.field = rejected.field;
  row.message = rejected.message;
  enqueue(
      [this, row = std::move(row)] {
        writeOrLog([&] { index_->rejected(row); }, "a rejection is not in the run index");
      },
      /*urgent=*/true);
}

std::optional<collision_lab::service::IndexedRun> RunIndexRecorder::find(const std::string& run_id) const {
  if (!ok()) return std::nullopt;
  try {
    return index_->find(run_id);
  } catch (const collision_lab::service::RunIndexError& e) {
    ROS_WARN_STREAM("the run index cannot tell whether run_id '" << run_id << "' was served: " << e.what());
    return std::nullopt;
  }
}

bool RunIndexRecorder::holds(const std::string& run_id) const {
  using collision_lab::service::RunState;
  const auto run = find(run_id);
  if (!run) return false;
  if (run->state == RunState::kQueued || run->state == RunState::kRunning) return true;
  std::error_code ec;
  return !run->bag_path.empty() && std::filesystem::exists(run->bag_path, ec);
}

std::uint64_t RunIndexRecorder::studentBagBytes(const std::string& student) const {
  if (!ok()) return 0;
  std::uint64_t bytes = 0;
  try {
    for (const auto& row : index_->list(student)) {
      std::error_code ec;
      const auto size = row.bag_path.empty() ? 0 : std::filesystem::file_size(row.bag_path, ec);
      if (!ec) bytes += size;
    }
  } catch (const collision_lab::service::RunIndexError& e) {
    ROS_WARN_STREAM("student '" << student << "': their bags are not counted: " << e.what());
  }
  return bytes;
}

std::vector<collision_lab::ServedRun> RunIndexRecorder::list(const std::string& student) const {
  std::vector<collision_lab::ServedRun> served;
  if (!index_) return served;
  if (!flush(kIndexCommitWait, /*unless_locked=*/true)) ROS_WARN("~list_runs: the newest runs wait to be written into the run index");
  std::vector<IndexedRun> rows;
  try {
    rows = index_->list(student.empty() ? std::nullopt : std::optional<std::string>(student));
  } catch (const RunIndexError& e) {
    ROS_ERROR_STREAM("~list_runs: the run index cannot be read: " << e.what());
    return served;
  }
  served.reserve(rows.size());
  for (const IndexedRun& row : rows) {
    collision_lab::ServedRun run;
    run.accepted.header.stamp.fromSec(row.accepted_at);
    run.accepted.run_id = row.run_id;
    run.accepted.requested_run_id = row.requested_run_id;
    run.accepted.student = row.student;
    run.finished = row.state == RunState::kFinished || row.state == RunState::kInterrupted;
    run.collision_count = row.collision_count;
    run.stop_reason = row.stop_reason;
    run.bag_path = row.bag_path;
    run.truncated = row.ending.truncated;
    run.recording_ok = !row.bag_path.empty();
    served.push_back(std::move(run));
  }
  return served;
}

bool RunIndexRecorder::endFromBag(const std::string& run_id, const std::string& bag_path, const BagContents& contents,
                                  const std::string& note) {
  // Made here, on the recovering thread: the writer thread only calls the index.
  std::optional<IndexedRun> unseen;
  if (contents.input) {  // the row of a run the index never saw (its node had no index)
    unseen.emplace();
    unseen->run_id = run_id;
    unseen->student = contents.input->student;
    unseen->accepted_at = contents.input->header.stamp.toSec();
    unseen->body_count = static_cast<std::uint32_t>(contents.input->masses.size());
    unseen->scene_json = inputJson(*contents.input);
  }
  std::optional<collision_lab::RunSummary> summary = contents.summary;
  std::string text;
  if (summary) {
    summary->bag_path = bag_path;
    summary->recording_ok = !bag_path.empty();
    text = summaryJson(*summary);
  } else {
    text = interruptedJson(bag_path, contents, note);
  }
  // Through the writer thread, as every write: never inside another group's transaction.
  auto ended = std::make_shared<std::atomic<bool>>(false);
  const std::uint64_t ticket = enqueue(
      [this, ended, run_id, bag_path, unseen, summary, text, note, events = contents.events] {
        writeOrLog(
            [&] {
              const auto row = index_->find(run_id);
              if (row && row->state == RunState::kFinished) {
                // Its end is known (e.g. its bag failed on a full disk, and the summary went to the index).
                ROS_WARN_STREAM("run " << run_id << ": its bag was left unfinished, and the index has the run as finished: its summary is kept ("
                                << (bag_path.empty() ? std::string("no bag") : "its bag " + bag_path) << ")");
                *ended = false;
                return;
              }
              if (!row && unseen) index_->accepted(*unseen);
              if (summary) {
                index_->finished(run_id, wallNow(), text, summary->stop_reason, summary->collision_count, bag_path,
                                 endingOf(*summary));
                ROS_INFO_STREAM("run " << run_id << ": completed from its bag's summary (" << note << ")");
              } else {
                index_->interrupted(run_id, wallNow(), text, events, bag_path);
                ROS_WARN_STREAM("run " << run_id << ": interrupted (" << note << "); its bag "
                                << (bag_path.empty() ? std::string("holds nothing") : bag_path + " holds " + std::to_string(events) + " events"));
              }
              *ended = true;
            },
            "run " + run_id + ": its end is not in the run index");
      },
      /*urgent=*/true);
  while (!waitWritten(ticket, kRecoveryWaitSlice) && !recovery_stops_) {
  }
  return *ended;
}

void RunIndexRecorder::takeRecoveredBags(const std::vector<RecoveredBag>& bags, std::size_t& ended) {
  for (const RecoveredBag& bag : bags) {
    if (recovery_stops_) return;
    if (!bag.error.empty()) {
      ROS_ERROR_STREAM("run " << bag.run_id << ": its bag left .active by a dead node was not recovered: " << bag.error);
    }
    if (!index_) continue;
    try {
      // An empty claim of a run still queued: it never started; ended or served again below.
      if (bag.bag_path.empty() && bag.error.empty()) {
        const auto row = index_->find(bag.run_id);
        if (row && row->state == RunState::kQueued) continue;
      }
      if (endFromBag(bag.run_id, bag.bag_path, bag.contents, "its node died; bag recovered from .active")) ++ended;
    } catch (const std::exception& e) {
      ROS_ERROR_STREAM("run " << bag.run_id << ": not recorded as interrupted: " << e.what());
    }
  }
}

void RunIndexRecorder::endOpenRuns(const ServeAgain& serve_again, bool queued_only,
                                   std::map<std::string, bool>& offered, std::size_t& ended) {
  std::vector<IndexedRun> open_runs;
  try {
    if (!queued_only) open_runs = index_->inState(RunState::kRunning);
    const auto queued = index_->inState(RunState::kQueued);
    open_runs.insert(open_runs.end(), queued.begin(), queued.end());
  } catch (const RunIndexError& e) {
    ROS_ERROR_STREAM("recovery: the run index cannot be read: " << e.what());
    return;
  }
  for (const IndexedRun& run : open_runs) {
    if (recovery_stops_) return;
    // This process's own runs (accepted since it started) are never a dead node's.
    if (run.accepted_at >= started_at_) continue;
    const std::string final_path = bagPath(bag_directory_, run.run_id);
    const std::string active_path = final_path + ".active";
    if (activeBagOwned(active_path)) continue;  // a live node's run
    if (queued_only && fs::exists(active_path)) continue;  // a dead node's bag: read in the second pass
    const auto before = offered.find(run.run_id);
    if (before != offered.end() && before->second) continue;  // served again
    if (serve_again && run.state == RunState::kQueued && !fs::exists(final_path) && before == offered.end()) {
      try {
        if ((offered[run.run_id] = serve_again(QueuedRun{inputFromJson(run.scene_json), run.requested_run_id}))) continue;
      } catch (const std::exception& e) {
        ROS_WARN_STREAM("run " << run.run_id << ": queued when its node died, and not served again: " << e.what());
      }
      if (activeBagOwned(active_path)) continue;  // another live node claimed it meanwhile
    }
    try {
      BagContents contents;
      std::string bag_path;
      if (fs::exists(final_path)) {
        contents = readBagContents(final_path);
        bag_path = final_path;
      }
      if (endFromBag(run.run_id, bag_path, contents, "its node died before the run finished")) ++ended;
    } catch (const std::exception& e) {
      ROS_ERROR_STREAM("run " << run.run_id << ": not recovered: " << e.what());
    }
  }
}

void RunIndexRecorder::stopRecovery() { recovery_stops_ = true; }

std::size_t RunIndexRecorder::recover(const ServeAgain& serve_again) {
  while (!flush(kRecoveryWaitSlice) && !recovery_stops_) {  // it reads the runs' states
  }
  std::size_t ended = 0;
  std::map<std::string, bool> offered;  // queued runs offered to serve_again (once each): taken
  // First what needs no bag read: the dead nodes' empty claims, then their queued runs,
  // served again at once.
  takeRecoveredBags(recoverActiveBags(bag_directory_, ActiveBags::kEmptyClaims), ended);
  if (index_ && !recovery_stops_) endOpenRuns(serve_again, /*queued_only=*/true, offered, ended);
  // Then their bags, reindexed (seconds for a big one), and every run still open.
  if (!recovery_stops_) takeRecoveredBags(recoverActiveBags(bag_directory_, ActiveBags::kAll), ended);
  if (index_ && !recovery_stops_) endOpenRuns(serve_again, /*queued_only=*/false, offered, ended);
  return ended;
}

}  // namespace collision_lab_ros
