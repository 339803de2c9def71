// Where the web node finds the runs it does not hold in memory (docs/web.md, "Memory and
// restarts"): the class's run index (service/run_index.h), which the lab node writes. The
// RunBook asks it for a run it has evicted or never seen (an old link after a restart), for
// the run list, and for the state of runs it believes queued or running (a summary it
// missed). An interface, so tests give a fake and the web node the SQLite index.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "collision_lab/service/run_index.h"

namespace collision_lab_web {

class RunSource {
 public:
  virtual ~RunSource() = default;
  /// The run's row; nullopt when the source does not know it. May throw (the RunBook then
  /// treats the run as unknown and logs nothing: the next call asks again).
  virtual std::optional<collision_lab::service::IndexedRun> find(const std::string& run_id) const = 0;
  /// Every run (only student's when given), oldest accepted first.
  virtual std::vector<collision_lab::service::IndexedRun> list(const std::optional<std::string>& student) const = 0;
  /// The lab node's rejected inputs (only student's when given), newest first, at most limit.
  virtual std::vector<collision_lab::service::IndexedRejection> rejections(const std::optional<std::string>& student,
                                                                          std::size_t limit) const = 0;
};

/// The SQLite run index at path (<bag_directory>/runs.sqlite) as a RunSource. Opening
/// creates the file when missing (the lab node may start later). Throws RunIndexError.
std::shared_ptr<const RunSource> openIndexRunSource(const std::string& path);

}  // namespace collision_lab_web
