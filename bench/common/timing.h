// Timing helpers for the benchmarks: wall-clock stopwatch, medians, and a sink that keeps
// the optimiser from deleting the work being timed. Machines are shared and noisy, so
// every figure is a median of repeats, and speeds are quoted as ratios against a
// baseline measured in the same process.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <vector>

namespace collision_lab {
namespace bench {

/// Forces `value` to be materialised (in memory), so the computation producing it runs.
template <class T>
inline void doNotOptimize(const T& value) {
  asm volatile("" : : "r,m"(value) : "memory");
}

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

/// Median of the samples (mean of the two middle ones for an even count); 0 when empty.
inline double median(std::vector<double> samples) {
  if (samples.empty()) return 0.0;
  std::sort(samples.begin(), samples.end());
  const std::size_t n = samples.size();
  return n % 2 == 1 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
}

/// Runs `work` `repeats` times and returns the wall time of each run [s].
template <class Work>
std::vector<double> timeRepeats(int repeats, Work&& work) {
  std::vector<double> samples;
  samples.reserve(static_cast<std::size_t>(repeats));
  for (int i = 0; i < repeats; ++i) {
    Stopwatch watch;
    work();
    samples.push_back(watch.seconds());
  }
  return samples;
}

}  // namespace bench
}  // namespace collision_lab
