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

  /// Called for every collision; reads the clock only every 2^16 collisions, and draws
  /// from one second after the start, at most five times a second.
  void onCollision(std::uint64_t index) {
    if ((index & 0xFFFF) == 0) maybeDraw(index, -1.0);
  }
  /// Called by the event engine every few impacts: impacts so far and simulated time [s].
  void onEngineProgress(std::uint64_t impacts, double time) { maybeDraw(impacts, time); }

 private:
  /// `time` [s] is the simulated time, or negative when not known.
  void maybeDraw(std::uint64_t index, double time);

  std::FILE* terminal_;
  std::uint64_t expected_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  bool drawn_ = false;
};

}  // namespace cli
}  // namespace collision_lab
