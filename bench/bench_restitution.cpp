// Benchmark (not a test): the impact count against the restitution e for three equal
// masses, x = (2, 1, 0) m, v = (-1, 0, 0) m/s, across the critical value r_c = 7 - 4 sqrt 3
// (issue 11). e runs from 0.05 to 1, dense near r_c on both sides (e - r_c = +-10^-k).
// For each e: the three_body_spiral prediction (count or collapse, with the collapse time),
// its time per call, and the exact engine's count, collapse and median time per run where
// an exact simulation can reach the end (the engine is skipped when the predicted count
// exceeds 2000: next to r_c the approach speeds fall below 10^-1000 of the velocities).
// Writes a CSV (default docs/restitution_count.csv); plot it with
// bench/plot_restitution_count.py.
//
//   collision_lab_bench_restitution [--csv FILE] [--repeats R]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/models.h"

namespace {

using namespace collision_lab::core;
using Clock = std::chrono::steady_clock;

Scene scene(double e) { return Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {e}}; }

template <class F>
double medianSeconds(int repeats, F&& f) {
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    const auto start = Clock::now();
    f();
    times.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

std::vector<double> restitutions(double rc) {
  std::vector<double> e;
  for (int k = 1; k <= 20; ++k) e.push_back(0.05 * k);
  for (double x = 0.06; x < 0.1; x += 0.002) e.push_back(x);
  for (int k = 2; k <= 9; ++k) e.push_back(rc + std::pow(10.0, -k)), e.push_back(rc - std::pow(10.0, -k));
  std::sort(e.begin(), e.end());
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  std::string csv_path = COLLISION_LAB_DOCS_DIR "/restitution_count.csv";
  int repeats = 5;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
    else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
    else {
      std::fprintf(stderr, "usage: %s [--csv FILE] [--repeats R]\n", argv[0]);
      return 2;
    }
  }
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) {
    std::fprintf(stderr, "cannot write %s\n", csv_path.c_str());
    return 1;
  }
  const double rc = *predictThreeBodySpiral(scene(0.5)).critical_restitution;
  std::fprintf(csv, "e,e_minus_rc,model_count,collapsed,collapse_time_s,model_time_s,engine_count,engine_collapsed,"
                    "engine_median_time_s,engine_truncated\n");
  std::printf("three equal masses, x = (2, 1, 0) m, v = (-1, 0, 0) m/s; r_c = %.17g\n", rc);
  std::printf("%-22s %-12s %-10s %-16s %-12s %-12s %-14s\n", "e", "e - r_c", "count", "collapse t [s]", "model [s]",
              "engine count", "engine [s]");
  for (double e : restitutions(rc)) {
    Prediction p;
    const double model_time = medianSeconds(repeats, [&] { p = predictThreeBodySpiral(scene(e)); });
    const long long count = p.impact_count ? static_cast<long long>(*p.impact_count) : -1;
    std::string engine_count = "", engine_time = "", engine_collapsed = "", engine_truncated = "";
    if (!p.collapsed ? count <= 2000 : std::fabs(e - rc) > 1e-4) {
      SceneSimulation run;
      const double t = medianSeconds(repeats, [&] { run = runEngine(scene(e)); });
      engine_count = std::to_string(run.impact_count);
      engine_truncated = run.stop == StopReason::kCap ? "1" : "0";
      engine_collapsed = run.collapsed ? "1" : "0";
      char buffer[32];
      std::snprintf(buffer, sizeof buffer, "%.3g", t);
      engine_time = buffer;
    }
    std::fprintf(csv, "%.17g,%.6g,%lld,%d,%.17g,%.3g,%s,%s,%s,%s\n", e, e - rc, count, p.collapsed ? 1 : 0,
                 p.collapse_time.value_or(NAN), model_time, engine_count.c_str(), engine_collapsed.c_str(),
                 engine_time.c_str(), engine_truncated.c_str());
    std::printf("%-22.17g %-12.3g %-10s %-16s %-12.3g %-12s %-14s\n", e, e - rc,
                p.collapsed ? "collapse" : std::to_string(count).c_str(),
                p.collapsed ? std::to_string(*p.collapse_time).c_str() : "", model_time,
                engine_count.empty()
                    ? "-"
                    : (engine_count + (engine_collapsed == "1" ? "+c" : "") + (engine_truncated == "1" ? "*" : "")).c_str(),
                engine_time.empty() ? "-" : engine_time.c_str());
  }
  std::fclose(csv);
  std::printf("engine count: +c a collapse resolved after the impacts counted; * stopped at the engine's exactness cap\n"
              "(truncated: next to r_c the approach speeds need ever more bits; the model counts these spirals)\n");
  std::printf("wrote %s\n", csv_path.c_str());
  return 0;
}
