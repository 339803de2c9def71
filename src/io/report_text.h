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

#include "collision_lab/io/report.h"  // Json
#include "text_sink.h"

namespace collision_lab {
namespace io {
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

/// A double for JSON: never a negative zero (NaN and infinities become null when dumped).
inline Json number(double value) { return Json(value == 0 ? 0.0 : value); }

/// Bodies at most for which an event record carries the full state (every body's arrays);
/// CollisionEvent::FULL_STATE_MAX_BODIES, the ROS message's limit, which the record mirrors.
constexpr std::size_t kFullStateMaxBodies = 64;

/// One event of any scene, in the one schema of JSON and CSV (docs/cli.md "Events"): the
/// fields of msg/CollisionEvent.msg. Pointers refer to the caller's arrays; a null pointer
/// (or full_state false) prints as JSON null and an empty CSV cell.
struct EventRecord {
  bool collapse = false;
  std::uint64_t index = 0;     ///< impact number; a collapse: the impacts before it
  std::size_t pair_index = 0;  ///< a collapse: its first body
  double time = 0.0, position = 0.0, restitution = 1.0;
  std::size_t first_moved = 0, last_moved = 0;
  bool cluster_impact = false;
  std::array<double, 2> pair_velocities_before{}, pair_velocities_after{}, pair_energy_transfer{};
  double energy_lost = 0.0;
  bool full_state = false;  ///< the arrays below have `bodies` entries
  std::size_t bodies = 0;
  const double* positions = nullptr;
  const double* velocities_before = nullptr;
  const double* velocities_after = nullptr;
  const double* energy_transfer = nullptr;
  const double* kinetic_energy_after = nullptr;
  double total_energy = 0.0, total_momentum = 0.0;
  /// The model's values (three bodies answered by the rotation); null otherwise.
  const std::array<double, 3>* predicted_velocities_after = nullptr;
  const std::array<double, 3>* predicted_energy_transfer = nullptr;
  const std::array<double, 3>* paper_velocities_after = nullptr;
  const std::array<double, 3>* paper_energy_transfer = nullptr;
};

/// The record of a three-body event (full state and the model's block from the event).
/// `positions` etc. point into `lab`, which must outlive the record.
EventRecord eventRecord(const core::LabEvent& lab);
/// The record as one compact JSON object.
void writeEventRecordJson(TextSink& sink, const EventRecord& record);
/// The record as one CSV row (with its line break), in the columns of kEventCsvHeader.
void writeEventRecordCsv(TextSink& sink, const EventRecord& record);
/// The one events header of every CSV report; per-body arrays are one cell each, values
/// separated by ';'.
extern const char* const kEventCsvHeader;

/// The bodies' state through an N-body run, from its impacts and collapses in order, for
/// their records (core::BodyStateReplay): the per-body arrays of a record only for scenes
/// of at most kFullStateMaxBodies bodies. A record refers to this object's arrays,
/// valid until the next impact() or collapse().
class SceneEventState {
 public:
  explicit SceneEventState(const core::Scene& scene);
  EventRecord impact(const core::ImpactRecord& impact);
  EventRecord collapse(const core::Collapse& collapse);

 private:
  void fill(EventRecord& record);

  core::Scene scene_;
  bool full_state_;
  core::BodyStateReplay replay_;  ///< the one replay of the records (core/nbody/body_state_replay.h)
  std::vector<double> positions_, before_, gain_;  ///< the record's arrays (full state only)
};

/// eventJson(lab) as compact JSON text (its keys in its order, numbers as writeJsonNumber),
/// written without building a document.
void writeEventJson(TextSink& sink, const core::LabEvent& lab);
/// The same as a line of the "events" array: "\n" before the first event, ",\n" before others.
void writeEventJsonLine(TextSink& sink, const core::LabEvent& lab, bool first);

}  // namespace report_text
}  // namespace io
}  // namespace collision_lab
