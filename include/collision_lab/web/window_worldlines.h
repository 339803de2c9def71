// The x-t diagram of a time window of a recorded run, for the page's zoom: every event in
// the window, read from the run's bag, instead of the run's bounded whole-run worldlines
// (which keep a long run's early impacts only as a few columns).
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace collision_lab_web {

struct WindowLine {
  std::size_t body = 0;
  std::vector<std::pair<double, double>> points;  ///< (t [s], x [m]), t increasing
};

struct WindowWorldlines {
  double from = 0.0, to = 0.0;  ///< [s]
  std::vector<WindowLine> lines;
  /// Every vertex kept (false: a line had more than max_vertices and is drawn per column,
  /// its first, lowest, highest and last x).
  bool exact = true;
};

/// The worldlines of `bodies` (indices of the run's bodies; others left out) from t = from to
/// t = to [s] of the run recorded in bag_path: each body's position at `from`, where each
/// event in the window leaves it, and at `to`, straight lines between (free flight). At most
/// max_vertices points per line. Throws std::runtime_error when the bag cannot be read or
/// has no InitialConditions, and std::invalid_argument for a ring (cut at its seam
/// elsewhere) or when not 0 <= from < to.
WindowWorldlines windowWorldlines(const std::string& bag_path, double from, double to,
                                  const std::vector<std::size_t>& bodies, std::size_t max_vertices);

}  // namespace collision_lab_web
