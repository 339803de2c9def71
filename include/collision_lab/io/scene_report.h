// Reports of scenes of any size (N bodies): the aligned table, JSON and CSV, with the model
// that answered and why. ROS-free. Conventions as report.h: SI units, doubles that read
// back to the same double, never -0, null for NaN and infinities (walls are named).
//
// One writer for every scene. A run whose prediction carries the rotation model's values
// (core::hasRotationValues: three elastic bodies) keeps the three-body layout of its scene
// and summary (report.h's keys), with the model added; its events are every scene's, with
// the impact's model block. Large scenes: the table shows the first and last kTableBodies
// bodies and says how many it leaves out; JSON and CSV carry every body.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/event_record.h"
#include "collision_lab/io/report.h"
#include "collision_lab/io/scenario_file.h"

namespace collision_lab {
namespace io {
class SceneEventState;

/// Bodies shown at each end of the table's body lists.
constexpr std::size_t kTableBodies = 5;

/// Writes the report of one run while it runs: begin(), then impact() and collapse() for
/// each event to show, in the order they happen, then end(). Nothing is kept per event.
class SceneReportWriter {
 public:
  virtual ~SceneReportWriter() = default;
  /// `prediction`: the plan's (core::ScenePlan), which decides the layout (above).
  virtual void begin(const SceneEntry& entry, const core::RunOptions& options, const core::ModelChoice& model,
                     const std::optional<core::Prediction>& prediction) = 0;
  virtual void impact(const core::ImpactRecord& impact) = 0;
  /// An inelastic collapse: an event of its own, not counted as a collision.
  virtual void collapse(const core::Collapse& collapse) = 0;
  virtual void end(const core::SceneRunResult& result) = 0;
};

std::unique_ptr<SceneReportWriter> makeSceneReportWriter(ReportFormat format, std::ostream& out);

/// The JSON report of one run as values, for a front end that keeps it in its own types
/// (the Python module): the scene, options, units, events and summary that the JSON report
/// (makeSceneReportWriter(kJson)) writes, key for key and value for value.
class ReportValues {
 public:
  virtual ~ReportValues() = default;
  /// The report's "scene", "options" and "units", before any event.
  virtual void head(const Json& scene, const Json& options, const Json& units) = 0;
  /// One event of "events" (the record is valid during the call; eventPairName names its pair).
  virtual void event(const EventRecord& record) = 0;
  /// The report's "summary", after the last event.
  virtual void summary(const Json& summary) = 0;
};

/// A report writer that hands its values to `values`, which must outlive it.
std::unique_ptr<SceneReportWriter> makeSceneReportValues(ReportValues& values);

/// How runReported runs a scene: the one path from a plan to its report of the CLI and the
/// Python module.
struct ReportedRun {
  core::RunOptions options;                   ///< as shown: the events the report gets
  bool simulate_to_cap = false;               ///< core::SceneRunOptions::simulate_to_cap
  const std::atomic<bool>* cancel = nullptr;  ///< set: the run stops, marked cancelled
  /// T(t) [J] written to this file (TemperatureCsv): the run is then simulated impact by
  /// impact even where the closed form answers (the report still shows what options ask).
  std::optional<std::string> temperature_csv;
  core::ProgressCallback progress;            ///< watches only: the run takes the same path
  std::uint64_t progress_interval = std::uint64_t{1} << 20;
};

/// Runs the planned scene (core::planScene, valid) and hands `report` its begin, the events
/// to show in order as they happen, and its end; nothing is kept per event. Throws
/// CannotOpenFile before anything is reported when the temperature file cannot be opened,
/// OutputFailed when it lost any of what was written.
core::SceneRunResult runReported(const SceneEntry& entry, const core::ScenePlan& plan, const ReportedRun& run,
                                 SceneReportWriter& report);

/// name, description, bodies (N), masses, positions, velocities, restitution, walls (names).
Json sceneEntryJson(const SceneEntry& entry);
/// The events of one N-body run as JSON objects, in the one event schema of every report
/// (docs/cli.md "Events", the fields of msg/CollisionEvent.msg). Give it every impact and
/// collapse of the run in order from the first: it tracks the bodies' state for the full-state
/// arrays (scenes of at most 64 bodies; null above).
class SceneEventJson {
 public:
  /// `policy`: which impacts carry every body's state (core::EventPolicy::fullStateAt).
  explicit SceneEventJson(const core::Scene& scene, const core::EventPolicy& policy = {});
  ~SceneEventJson();
  Json impact(const core::ImpactRecord& impact);
  Json collapse(const core::Collapse& collapse);

 private:
  std::unique_ptr<SceneEventState> state_;
};
/// The summary of an N-body run (see docs/cli.md for the keys).
Json sceneSummaryJson(const core::SceneRunResult& result);

/// One scene of a batch and its finished run.
struct SceneBatchOutcome {
  SceneEntry entry;
  core::RunOptions options;  ///< as run (a scene's own max_collisions applied)
  core::SceneRunResult result;
};

/// Several scenes of any size, in one format whatever the scenes are: table and CSV give one
/// row per scene (scenario, bodies, model, collision count and predicted count, truncated,
/// energy lost); JSON gives {"units", "scenarios": [{"scene", "options", "events",
/// "summary"}, ...]}, each scene's summary as its single-scene report has it.
void writeSceneBatchReport(ReportFormat format, const std::vector<SceneBatchOutcome>& outcomes, std::ostream& out);

}  // namespace io
}  // namespace collision_lab
