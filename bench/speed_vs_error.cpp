// collision_lab_speed_vs_error (issue 4): the same scenes through every method, timed and
// measured against the exact reference, written as CSV, Markdown and a PNG plot.
//
// Methods: event_double, event_long_double, event_high (the core's event simulation),
// closed_form (the core's count and O(1) state after n collisions), fixed_step (a
// hand-written time-stepping loop), and every real engine this build found (Bullet, ODE,
// Box2D), each swept over dt. Reference: exact rationals (collision count, velocities by
// exact::simulate; positions by an independent GMP trajectory, bench/common).
//
// Usage: collision_lab_speed_vs_error [--quick] [--csv FILE] [--md FILE] [--plot FILE]
//   The full run (no --quick) writes docs/speed_vs_error.{csv,md,png} unless told
//   otherwise. --quick (fewer scenes and dt values, under a minute) writes only the files
//   named on the command line and prints the table. Progress goes to stderr.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/simulation.h"
#include "exact_trajectory.h"
#include "report.h"
#include "stepped.h"
#include "timing.h"

using namespace collision_lab;
using namespace collision_lab::core;
using namespace collision_lab::bench;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Every scene ends its last collision before this time; every method is compared here [s].
constexpr double kEndTime = 3.0;

struct BenchScene {
  std::string name;
  std::string description;
  ThreeBodyScene scene;
  bool in_quick;
};

/// Positions are generic decimals, off every dt grid: with round numbers the collisions
/// of a simple scene can fall exactly on step boundaries and a stepper looks exact by luck.
std::vector<BenchScene> benchScenes() {
  return {
      {"equal", "equal masses, 3 collisions", {{1, 1, 1}, {1.0371, 0, -1.5193}, {-1, 0, 1}}, true},
      {"general_123", "masses (1, 2, 3)", {{1, 2, 3}, {1.0371, 0, -1.5193}, {-1, 0, 1}}, true},
      {"pi_100", "pi billiard, wall, 100:1 (31)", {{100, 1, kInf}, {1.0371, 0.5193, 0}, {-1, 0, 0}}, true},
      {"pi_1e6", "pi billiard, wall, 10^6:1 (3141)", {{1e6, 1, kInf}, {1.0371, 0.5193, 0}, {-1, 0, 0}}, false},
      {"heavy_light_heavy", "(1e6, 1, 1e6)", {{1e6, 1, 1e6}, {0.5371, 0, -0.4829}, {-1, 0, 0}}, false},
      {"grazing", "grazing (3, 1, 0.5): last contact at speed 0",
       {{3, 1, 0.5}, {1.0371, 0, -0.9193}, {-1, 0, 0}}, true},
      // t_BC < t_AB by a few ulps: BC is first (3 collisions); naive double picks AB (2).
      {"near_triple", "near-triple (1, 3, 1): BC first by ulps",
       {{1, 3, 1}, {0.9371, 0, -0.23427499999999998}, {-0.7, 0.1, 0.3}}, true},
  };
}

struct Reference {
  std::uint64_t collision_count = 0;
  std::optional<Pair> first_pair;
  std::array<double, 3> velocities{};
  std::array<double, 3> positions_at_end{};
  double last_collision_time = 0.0;
  std::string check;  ///< how exact::simulate and the GMP trajectory agreed
};

Reference makeReference(const BenchScene& bench_scene) {
  Reference ref;
  const ExactTrajectory trajectory(bench_scene.scene, 10'000'000);
  ref.collision_count = trajectory.collisionCount();
  ref.first_pair = trajectory.firstPair();
  ref.velocities = trajectory.finalVelocities();
  ref.positions_at_end = trajectory.positionsAt(kEndTime);
  ref.last_collision_time = trajectory.lastCollisionTime();
  {
    const exact::Run run = exact::simulate(bench_scene.scene, 10'000'000);
    std::array<double, 3> v{};
    for (int i = 0; i < 3; ++i) v[i] = static_cast<double>(run.final_velocities[i]);
    const double diff = relativeVelocityError(bench_scene.scene, ref.velocities, v);
    const bool agree = run.collision_count == ref.collision_count && run.first_pair == ref.first_pair &&
                       diff <= 4 * std::numeric_limits<double>::epsilon();
    ref.check = agree ? "exact::simulate agrees (count, first pair, velocities to rounding)"
                      : format("MISMATCH: exact::simulate count %llu, velocity difference %s",
                               static_cast<unsigned long long>(run.collision_count), sci(diff).c_str());
    ref.velocities = v;  // exact::simulate is the stated reference for velocities
    if (!agree) std::fprintf(stderr, "warning: %s: %s\n", bench_scene.name.c_str(), ref.check.c_str());
  }
  return ref;
}

struct Row {
  std::string method;
  std::string scene;
  std::string parameter;
  double wall_time_s = 0.0;
  int runs = 0;
  std::uint64_t collisions = 0;
  std::int64_t count_error = 0;
  double velocity_rel_error = 0.0;
  double energy_rel_drift = 0.0;
  double position_abs_error = NAN;
};

/// Median wall time of `work` [s]. Work taking under a millisecond is timed in batches;
/// repeats: 5 below 0.2 s, 3 below 3 s, else 1 (quick mode: 3, else 1).
template <class Work>
double medianTime(Work&& work, bool quick, int* runs) {
  Stopwatch first;
  work();
  const double t1 = first.seconds();
  int batch = 1;
  if (t1 < 1e-3) batch = static_cast<int>(std::min(1e5, std::ceil(1e-3 / std::max(t1, 1e-8))));
  const int repeats = quick ? (t1 < 0.2 ? 3 : 1) : (t1 < 0.2 ? 5 : (t1 < 3.0 ? 3 : 1));
  if (batch == 1 && repeats == 1) {
    *runs = 1;
    return t1;
  }
  const auto samples = timeRepeats(repeats, [&] {
    for (int i = 0; i < batch; ++i) work();
  });
  *runs = repeats * batch;
  return median(samples) / batch;
}

double maxAbsDiff(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  double worst = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double d = std::fabs(a[i] - b[i]);
    if (std::isnan(d)) return NAN;
    worst = std::max(worst, d);
  }
  return worst;
}

Row makeRow(const std::string& method, const BenchScene& s, const std::string& parameter,
            const Reference& ref, double time, int runs, std::uint64_t collisions,
            const std::array<double, 3>& v, const std::optional<std::array<double, 3>>& x_end) {
  Row row;
  row.method = method;
  row.scene = s.name;
  row.parameter = parameter;
  row.wall_time_s = time;
  row.runs = runs;
  row.collisions = collisions;
  row.count_error = static_cast<std::int64_t>(collisions) - static_cast<std::int64_t>(ref.collision_count);
  row.velocity_rel_error = relativeVelocityError(s.scene, v, ref.velocities);
  row.energy_rel_drift = energyRelativeDrift(s.scene, v);
  if (x_end) row.position_abs_error = maxAbsDiff(*x_end, ref.positions_at_end);
  return row;
}

Row runEvent(Precision precision, const BenchScene& s, const Reference& ref, bool quick) {
  SimulationOptions options;
  options.max_collisions = 10'000'000;
  options.events = EventPolicy::none();
  SimulationResult result;
  // A visitor makes the core track positions (final_positions at final_time).
  auto work = [&] { result = simulate(s.scene, options, precision, [](const ImpactEvent&) {}); };
  int runs = 0;
  const double time = medianTime(work, quick, &runs);
  std::array<double, 3> x_end{};
  for (int i = 0; i < 3; ++i) {
    x_end[i] = result.final_positions[i] + result.final_velocities[i] * (kEndTime - result.final_time);
  }
  const std::string name = std::string("event_") +
                           (precision == Precision::kDouble ? "double"
                            : precision == Precision::kLongDouble ? "long_double" : "high");
  return makeRow(name, s, precisionName(precision), ref, time, runs, result.collision_count,
                 result.final_velocities, x_end);
}

Row runClosedForm(const BenchScene& s, const Reference& ref, bool quick) {
  std::uint64_t count = 0;
  std::array<double, 3> v{};
  auto work = [&] {
    count = predictedCollisionCount(s.scene);
    const AnalyticModel<double> model(s.scene);
    const auto after = model.velocitiesAfter(count);
    for (int i = 0; i < 3; ++i) v[i] = after[i];
  };
  int runs = 0;
  const double time = medianTime(work, quick, &runs);
  return makeRow("closed_form", s, "double", ref, time, runs, count, v, std::nullopt);
}

Row runStepped(const SteppedMethod& method, double dt, const BenchScene& s, const Reference& ref,
               bool quick) {
  SteppedRun result;
  const StepConfig config{dt, kEndTime};
  auto work = [&] { result = method.run(s.scene, config); };
  int runs = 0;
  const double time = medianTime(work, quick, &runs);
  return makeRow(method.name, s, format("%g", dt), ref, time, runs, result.collisions, result.velocities,
                 result.positions);
}

std::string csvNumber(double value) { return std::isnan(value) ? "nan" : format("%.6e", value); }

std::string toCsv(const std::vector<Row>& rows) {
  std::ostringstream out;
  out << "method,scene,parameter,wall_time_s,collisions,count_error,velocity_rel_error,"
         "energy_rel_drift,position_abs_error\n";
  for (const auto& r : rows) {
    out << r.method << ',' << r.scene << ',' << r.parameter << ',' << csvNumber(r.wall_time_s) << ','
        << r.collisions << ',' << r.count_error << ',' << csvNumber(r.velocity_rel_error) << ','
        << csvNumber(r.energy_rel_drift) << ',' << csvNumber(r.position_abs_error) << '\n';
  }
  return out.str();
}

bool isOurs(const std::string& method) { return method.rfind("event_", 0) == 0 || method == "closed_form"; }

/// The "Done when" checks of issue 4, as measured.
std::string doneWhen(const std::vector<Row>& rows, const std::vector<BenchScene>& scenes,
                     const std::vector<SteppedMethod>& stepped) {
  std::ostringstream out;
  out << "## Checks (measured, not asserted)\n\n";
  int bad = 0;
  for (const auto& r : rows) {
    if (!isOurs(r.method)) continue;
    const bool pos_ok = r.method == "closed_form" || r.position_abs_error <= 1e-9;
    if (r.count_error != 0 || !(r.velocity_rel_error <= 1e-12) || !pos_ok) {
      ++bad;
      out << "- **Missed**: " << r.method << " on " << r.scene << ": count error " << r.count_error
          << ", velocity error " << sci(r.velocity_rel_error) << ", position error "
          << sci(r.position_abs_error) << ".\n";
    }
  }
  if (bad == 0) {
    out << "- Our exact methods: count error 0, velocity error <= 1e-12 and position error "
           "<= 1e-9 m on every scene (closed_form has no positions): **met**.\n";
  }
  const int engines = static_cast<int>(stepped.size()) - 1;
  out << "- Real engines measured: " << engines << " (goal at least 2: " << (engines >= 2 ? "**met**" : "**missed**")
      << ").\n";
  out << "- Cost for a stepping method to reach our accuracy on each scene (count error 0, "
         "velocity error <= max(1e-12, event_double's), position error <= max(1e-9 m, "
         "event_double's)), as a multiple of event_double's time (goal: >= 100x or never):\n\n";
  out << "| scene |";
  for (const auto& m : stepped) out << ' ' << m.name << " |";
  out << "\n|---|";
  for (std::size_t i = 0; i < stepped.size(); ++i) out << "---|";
  out << '\n';
  bool all_met = true;
  for (const auto& s : scenes) {
    const Row* ours = nullptr;
    for (const auto& r : rows) {
      if (r.scene == s.name && r.method == "event_double") ours = &r;
    }
    if (!ours) continue;
    out << "| " << s.name << " |";
    for (const auto& m : stepped) {
      const Row* best = nullptr;
      for (const auto& r : rows) {
        if (r.scene != s.name || r.method != m.name) continue;
        const bool reached = r.count_error == 0 &&
                             r.velocity_rel_error <= std::max(1e-12, ours->velocity_rel_error) &&
                             r.position_abs_error <= std::max(1e-9, ours->position_abs_error);
        if (reached && (!best || r.wall_time_s < best->wall_time_s)) best = &r;
      }
      if (!best) {
        out << " never reached |";
      } else {
        const double ratio = best->wall_time_s / ours->wall_time_s;
        if (ratio < 100) all_met = false;
        out << ' ' << format("%.3gx (dt %s)", ratio, best->parameter.c_str()) << " |";
      }
    }
    out << '\n';
  }
  out << "\nEvery stepping method needs at least 100x our time or never gets there: "
      << (all_met ? "**met**" : "**missed**") << ".\n\n";
  return out.str();
}

/// One line per scene: our event simulation in double against the most accurate
/// trajectory each stepping method reached (over its dt sweep, right count or not).
std::string summary(const std::vector<Row>& rows, const std::vector<BenchScene>& scenes,
                    const std::vector<Reference>& refs, const std::vector<SteppedMethod>& stepped) {
  std::ostringstream out;
  out << "## Summary\n\nevent_double against the smallest trajectory error each stepping method "
         "reached over its dt sweep: *position error [m] (count error) at dt, time*.\n\n"
      << "| scene | exact N | event_double: time, velocity err, position err [m] |";
  for (const auto& m : stepped) out << " best " << m.name << " |";
  out << "\n|---|---|---|";
  for (std::size_t i = 0; i < stepped.size(); ++i) out << "---|";
  out << '\n';
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const auto& s = scenes[k];
    const Row* ours = nullptr;
    for (const auto& r : rows) {
      if (r.scene == s.name && r.method == "event_double") ours = &r;
    }
    if (!ours) continue;
    out << "| " << s.name << " | " << refs[k].collision_count << " | "
        << format("%s s, %s, %s", sci(ours->wall_time_s).c_str(), sci(ours->velocity_rel_error).c_str(),
                  sci(ours->position_abs_error).c_str())
        << " |";
    for (const auto& m : stepped) {
      const Row* best = nullptr;
      for (const auto& r : rows) {
        if (r.scene == s.name && r.method == m.name &&
            (!best || r.position_abs_error < best->position_abs_error)) {
          best = &r;
        }
      }
      if (!best) {
        out << " - |";
        continue;
      }
      out << ' '
          << format("%s (%+lld) at dt %s, %s s", sci(best->position_abs_error).c_str(),
                    static_cast<long long>(best->count_error), best->parameter.c_str(), sci(best->wall_time_s).c_str())
          << " |";
    }
    out << '\n';
  }
  out << '\n';
  return out.str();
}

std::string toMarkdown(const std::vector<Row>& rows, const std::vector<BenchScene>& scenes,
                       const std::vector<Reference>& refs, const std::vector<SteppedMethod>& stepped,
                       bool quick, const std::string& command) {
  std::ostringstream out;
  out << "# Speed against error\n\n"
      << "Generated by `collision_lab_speed_vs_error` (bench/speed_vs_error.cpp)"
      << (quick ? " in **quick** mode" : "") << " on source " << sourceVersion()
      << ". Regenerate everything in docs/ with:\n\n"
      << "```\n" << command << "\n```\n\n"
      << "Every scene runs from t = 0 to t = " << kEndTime
      << " s, after its last exact collision, and every method is compared with the exact "
         "reference at that instant.\n\n"
      << "- **wall_time_s**: median wall time of one run [s] (runs column: how many runs "
         "the median is over; sub-millisecond runs are timed in batches). This machine is "
         "shared (" << std::thread::hardware_concurrency() << " hardware threads); read ratios, not absolutes.\n"
      << "- **count_error**: collisions counted minus the exact count. Stepping methods count "
         "a collision when a pair goes from approaching to not approaching between two steps.\n"
      << "- **velocity_rel_error**: max_i |v_i - v_i,exact| / max_i |v_i,exact| at the end, "
         "finite masses only.\n"
      << "- **energy_rel_drift**: |E_end - E_0| / E_0, kinetic energy of the finite masses.\n"
      << "- **position_abs_error**: max_i |x_i(" << kEndTime << " s) - x_i,exact| [m], the "
         "trajectory error. closed_form gives velocities and the count, not positions (nan).\n\n"
      << "Reference: collision count and final velocities from `exact::simulate` (Boost "
         "cpp_rational, exact for the input doubles); positions from an independent exact "
         "GMP rational trajectory (bench/common/exact_trajectory.cpp), rounded to double.\n\n";

  out << "## Scenes\n\n| scene | what | masses [kg] | positions [m] | velocities [m/s] | exact "
         "collisions | first pair | last collision [s] | reference check |\n"
         "|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const auto& s = scenes[i];
    out << "| " << s.name << " | " << s.description << " | " << triple(s.scene.masses) << " | "
        << format("(%.17g, %.17g, %.17g)", s.scene.positions[0], s.scene.positions[1], s.scene.positions[2])
        << " | " << triple(s.scene.velocities) << " | " << refs[i].collision_count << " | "
        << (refs[i].first_pair ? pairName(*refs[i].first_pair) : "-") << " | "
        << format("%.6f", refs[i].last_collision_time) << " | " << refs[i].check << " |\n";
  }
  out << "\nA wall (mass inf) is a static sphere in Bullet, a plane in ODE and a static circle in Box2D.\n\n";

  out << "## Methods and every setting\n\n"
      << "- **event_double, event_long_double, event_high**: the core's event-driven "
         "simulation, `simulate(scene, options, Precision)`, with a no-op visitor so it "
         "tracks positions; positions at the end time are final_positions + final_velocities "
         "(t_end - final_time).\n"
      << "- **closed_form**: `predictedCollisionCount(scene)`, then "
         "`AnalyticModel<double>(scene).velocitiesAfter(count)`; the time includes both.\n";
  for (const auto& m : stepped) out << "- **" << m.name << "**: " << m.settings << "\n";
  out << "\nAll engines use spheres (circles) of radius " << kEngineRadius
      << " m; centres are shifted by the radii (A by +2r, C by -2r) so bodies touch "
         "exactly when the point masses would, and shifted back when read.\n\n";

  out << summary(rows, scenes, refs, stepped);
  out << doneWhen(rows, scenes, stepped);

  out << "## Results\n\n";
  for (const auto& s : scenes) {
    out << "### " << s.name << "\n\n| method | parameter | wall_time_s | runs | collisions | count_error | "
           "velocity_rel_error | energy_rel_drift | position_abs_error [m] |\n"
           "|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : rows) {
      if (r.scene != s.name) continue;
      out << "| " << r.method << " | " << r.parameter << " | " << sci(r.wall_time_s) << " | " << r.runs
          << " | " << r.collisions << " | " << r.count_error << " | " << sci(r.velocity_rel_error) << " | "
          << sci(r.energy_rel_drift) << " | "
          << (std::isnan(r.position_abs_error) ? std::string("n/a") : sci(r.position_abs_error)) << " |\n";
    }
    out << '\n';
  }
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string csv_path, md_path, plot_path;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") {
      quick = true;
    } else if ((arg == "--csv" || arg == "--md" || arg == "--plot") && i + 1 < argc) {
      (arg == "--csv" ? csv_path : arg == "--md" ? md_path : plot_path) = argv[++i];
    } else {
      std::fprintf(stderr, "usage: %s [--quick] [--csv FILE] [--md FILE] [--plot FILE]\n", argv[0]);
      return 2;
    }
  }
  if (!quick) {
    const std::string docs = COLLISION_LAB_DOCS_DIR;
    if (csv_path.empty()) csv_path = docs + "/speed_vs_error.csv";
    if (md_path.empty()) md_path = docs + "/speed_vs_error.md";
    if (plot_path.empty()) plot_path = docs + "/speed_vs_error.png";
  }

  std::vector<BenchScene> scenes;
  for (auto& s : benchScenes()) {
    if (!quick || s.in_quick) scenes.push_back(s);
  }
  const std::vector<SteppedMethod> stepped = steppedMethods();
  const std::vector<double> dts_fixed =
      quick ? std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5} : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
  const std::vector<double> dts_engine =
      quick ? std::vector<double>{1e-2, 1e-3, 1e-4} : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5, 1e-6};

  Stopwatch total;
  std::vector<Reference> refs;
  for (const auto& s : scenes) {
    std::fprintf(stderr, "[reference] %s ...", s.name.c_str());
    Stopwatch watch;
    refs.push_back(makeReference(s));
    std::fprintf(stderr, " %llu collisions, %.1f s\n",
                 static_cast<unsigned long long>(refs.back().collision_count), watch.seconds());
  }

  std::vector<Row> rows;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const auto& s = scenes[k];
    const auto& ref = refs[k];
    auto note = [&](const Row& r) {
      std::fprintf(stderr, "[%s] %-18s %-10s %10.3e s  count error %+lld  pos error %s  (%.0f s total)\n",
                   s.name.c_str(), r.method.c_str(), r.parameter.c_str(), r.wall_time_s,
                   static_cast<long long>(r.count_error), sci(r.position_abs_error).c_str(), total.seconds());
    };
    for (Precision p : {Precision::kDouble, Precision::kLongDouble, Precision::kHigh}) {
      rows.push_back(runEvent(p, s, ref, quick));
      note(rows.back());
    }
    rows.push_back(runClosedForm(s, ref, quick));
    note(rows.back());
    for (const auto& method : stepped) {
      for (double dt : method.name == "fixed_step" ? dts_fixed : dts_engine) {
        rows.push_back(runStepped(method, dt, s, ref, quick));
        note(rows.back());
      }
    }
  }

  const std::string command =
      "bench/run_benchmarks.sh   # builds build_bench/ (Release), then writes docs/speed_vs_error.{csv,md,png}\n"
      "                          # and docs/hard_cases.md, and prints collision_lab_bench_core";
  const std::string csv = toCsv(rows);
  const std::string md = toMarkdown(rows, scenes, refs, stepped, quick, command);
  std::fputs(md.c_str(), stdout);
  bool ok = true;
  if (!csv_path.empty()) ok = writeTextFile(csv_path, csv) && ok;
  if (!md_path.empty()) ok = writeTextFile(md_path, md) && ok;
  if (!plot_path.empty()) {
    if (csv_path.empty()) {
      csv_path = plot_path + ".csv";
      ok = writeTextFile(csv_path, csv) && ok;
    }
    const std::string plot = std::string(COLLISION_LAB_PLOT_PYTHON) + " " + COLLISION_LAB_BENCH_DIR +
                             "/plot_speed_vs_error.py --csv '" + csv_path + "' --out '" + plot_path + "'" +
                             (quick ? " --title-suffix ' (quick mode)'" : "");
    std::fprintf(stderr, "[plot] %s\n", plot.c_str());
    if (std::system(plot.c_str()) != 0) {
      std::fprintf(stderr, "error: the plot script failed\n");
      ok = false;
    }
  }
  std::fprintf(stderr, "done in %.1f s\n", total.seconds());
  return ok ? 0 : 1;
}
