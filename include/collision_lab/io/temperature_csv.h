// The granular temperature T(t) of one run (core/nbody/temperature.h) as a CSV file,
// written while the run goes on: collision_lab_cli --temperature-csv FILE and
// collision_lab.run(temperature_csv=...). ROS-free.
#pragma once

#include <fstream>
#include <stdexcept>
#include <string>

#include "collision_lab/core/nbody/temperature.h"
#include "collision_lab/core/scene_run.h"

namespace collision_lab {
namespace io {

/// The file cannot be opened for writing (bad input: the path).
struct CannotOpenFile : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A file asked for lost some of what was written to it (the CLI's exit code 3).
struct OutputFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The CSV: `#` lines with T's definition, the header impacts,time_s,temperature_J, a row
/// at the start, after every temperatureStride(N)-th impact and after every collapse, and
/// the run's last impact; then `# haff_fit,...` lines: T0 and tau fitted on ln T over the
/// rows thinned to LogTimeSamples (50 per decade of time).
class TemperatureCsv {
 public:
  /// Opens `path`. Throws CannotOpenFile when it cannot.
  TemperatureCsv(const std::string& path, const core::Scene& scene);
  TemperatureCsv(const TemperatureCsv&) = delete;  // its sampler writes through `this`
  TemperatureCsv& operator=(const TemperatureCsv&) = delete;

  /// `visitors`, which also feed T(t): the event engine's impacts and collapses, or the
  /// three-body path's events.
  core::SceneVisitors feeding(core::SceneVisitors visitors);

  /// Writes the last row and the fit, and closes the file. Throws OutputFailed when the
  /// file lost any of it.
  void finish();

 private:
  void write(const core::TemperatureSample& sample);

  std::string path_;
  std::ofstream out_;
  std::vector<double> masses_;
  bool header_written_ = false;
  core::LogTimeSamples thinned_;
  core::TemperatureSampler sampler_;  ///< last: it writes the start's row when constructed
};

}  // namespace io
}  // namespace collision_lab
