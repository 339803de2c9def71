// A progress line on stderr for long runs, shown only when stderr is a terminal.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>

namespace collision_lab {
namespace cli {

class ProgressLine {
 public:
  /// `expected` is the predicted number of collisions (the cap, if lower); 0 when unknown.
  ProgressLine(std::FILE* terminal, std::uint64_t expected);
  ~ProgressLine();  ///< erases the line, if one was drawn

  /// Called by the run every few impacts: impacts so far and simulated time [s] (NaN when
  /// the run takes no impact times). Draws from one second after the start, at most five
  /// times a second.
  void onEngineProgress(std::uint64_t impacts, double time) { maybeDraw(impacts, time); }

 private:
  void maybeDraw(std::uint64_t index, double time);

  std::FILE* terminal_;
  std::uint64_t expected_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  bool drawn_ = false;
};

}  // namespace cli
}  // namespace collision_lab
