// Text helpers shared by the three-body report (report.cpp) and the N-body report
// (scene_report.cpp). Internal to collision_lab_io.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "collision_lab/core/nbody/body_state_replay.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/scene.h"

#include <memory>
#include <ostream>

#include "collision_lab/io/event_record.h"  // EventRecord, SceneEventState
#include "collision_lab/io/report.h"  // Json
#include "text_sink.h"

namespace collision_lab {
namespace io {

/// The layout of a run whose prediction carries the rotation model's values
/// (core::hasRotationValues): its scene, event table and summary beside the closed form and
/// the paper's values (docs/cli.md). The scene report (scene_report.h) writes through it for
/// such a run: begin(), then event() for each event to show, then end(); nothing is kept per
/// event.
class RunReportWriter {
 public:
  virtual ~RunReportWriter() = default;
  virtual void begin(const SceneEntry& scene, const core::RunOptions& options) = 0;
  virtual void event(const core::ImpactRecord& event) = 0;
  virtual void end(const core::SceneRunResult& result) = 0;
};

std::unique_ptr<RunReportWriter> makeRunReportWriter(ReportFormat format, std::ostream& out);

namespace report_text {

/// Compact text for people, `digits` significant digits; -0 is shown as 0, any NaN as nan.
inline std::string humanText(double value, int digits) {
  if (value == 0.0) return "0";
  if (std::isnan(value)) return "nan";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
  return buffer;
}

inline std::string padLeft(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : std::string(width - text.size(), ' ') + text;
}

inline std::string padRight(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}

/// The note of a run with time_beyond_range (core::SceneSimulation), in every report.
inline const char* const kTimeBeyondRangeNote =
    "the last impacts come after t = 1.8e+308 s, the largest double: counted, with exact velocities, their times "
    "(and any position past 1.8e+308 m) shown as inf, and the places of moving bodies not in them as nan (both null "
    "in JSON); a longer unit of time brings them into range";

/// A double for JSON: never a negative zero (NaN and infinities become null when dumped).
inline Json number(double value) { return Json(value == 0 ? 0.0 : value); }

/// The record of an impact with a model block (its full state and the model's values);
/// without one (leanImpact), the pair's values only. `positions` etc. point into `impact`,
/// which must outlive the record.
EventRecord eventRecord(const core::ImpactRecord& impact);
/// The impact as policy.fullStateAt(its index) says: itself, or its lean copy (the pair's
/// values from the model block, the block dropped).
core::ImpactRecord shownImpact(const core::ImpactRecord& impact, const core::EventPolicy& policy);
/// The record as one compact JSON object.
void writeEventRecordJson(TextSink& sink, const EventRecord& record);
/// The record as one CSV row (with its line break), in the columns of kEventCsvHeader.
void writeEventRecordCsv(TextSink& sink, const EventRecord& record);
/// The one events header of every CSV report; per-body arrays are one cell each, values
/// separated by ';'.
extern const char* const kEventCsvHeader;

/// eventJson(impact) as compact JSON text (its keys in its order, numbers as writeJsonNumber),
/// written without building a document.
void writeEventJson(TextSink& sink, const core::ImpactRecord& impact);
/// The same as a line of the "events" array: "\n" before the first event, ",\n" before others.
void writeEventJsonLine(TextSink& sink, const core::ImpactRecord& impact, bool first);

}  // namespace report_text
}  // namespace io
}  // namespace collision_lab
