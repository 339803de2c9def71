// collision_lab_speed_vs_error (issues 4 and 13): the same scenes through every method,
// timed and measured against the exact reference, written as CSV, Markdown and a PNG plot.
//
// Scenes: three-body elastic scenes, and N-body and restitution scenes (the presets of
// config/scenarios.yaml where they exist). Methods: closed_form (the three-body count and
// O(1) state after n collisions) on the three-body scenes; nbody_engine (the exact event
// engine, runEngine, the one simulator of every run) on every scene and model (the closed-form model that answers the scene,
// models.h) where one does; fixed_step (a hand-written time-stepping loop) and every real
// engine this build found (Bullet, ODE, Box2D, restitution set per pair), each swept over dt.
// Reference: exact rationals (an independent GMP trajectory, bench/common; on the
// three-body scenes also exact::walkVelocityMaps for counts and velocities).
//
// Usage: collision_lab_speed_vs_error [--quick] [--csv FILE] [--md FILE] [--plot FILE]
//   The full run (no --quick) writes docs/speed_vs_error.{csv,md,png} unless told
//   otherwise. --quick (fewer scenes and dt values) writes only the files named on the
//   command line and prints the table. Progress goes to stderr; the last line on stdout is
//   the issue-13 `goal:` line.
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
#include "collision_lab/core/nbody/body_state_replay.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/models.h"
#include "exact_trajectory.h"
#include "report.h"
#include "stepped.h"
#include "timing.h"

using namespace collision_lab;
using namespace collision_lab::core;
using namespace collision_lab::bench;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Every three-body scene ends its last collision before this time; it is compared here [s].
constexpr double kThreeBodyEndTime = 3.0;

struct BenchScene {
  std::string name;
  std::string description;
  Scene scene;                          ///< run by every method
  std::optional<Scene> three;           ///< the same scene where it is three elastic bodies: closed_form
  double end_time = kThreeBodyEndTime;  ///< every method is compared at this instant [s]
  bool in_quick = true;
  std::string preset;                     ///< the config/scenarios.yaml scene it follows, if any
  std::optional<std::uint64_t> known_count;  ///< impacts before end_time, from physics.md or the preset
  std::uint64_t engine_cap = 10'000'000;  ///< runEngine's max_impacts (the preset's cap where it has one)
};

BenchScene threeBody(std::string name, std::string description, const Scene& three, bool in_quick) {
  BenchScene s;
  s.name = std::move(name);
  s.description = std::move(description);
  s.scene = three;
  s.three = three;
  s.in_quick = in_quick;
  return s;
}

BenchScene nBody(std::string name, std::string description, Scene scene, double end_time, std::string preset,
                 std::optional<std::uint64_t> known_count, std::uint64_t engine_cap = 10'000'000) {
  BenchScene s;
  s.name = std::move(name);
  s.description = std::move(description);
  s.scene = std::move(scene);
  s.end_time = end_time;
  s.preset = std::move(preset);
  s.known_count = known_count;
  s.engine_cap = engine_cap;
  return s;
}

/// Positions are generic decimals, off every dt grid: with round numbers the collisions
/// of a simple scene can fall exactly on step boundaries and a stepper looks exact by luck.
/// The N-body and restitution scenes keep their preset's masses, velocities and e, with
/// the positions moved off the grid down to 1e-7 s (7 decimals: with v = -1 m/s a 4-decimal
/// gap puts the first impact on the 1e-4 s grid).
std::vector<BenchScene> benchScenes() {
  std::vector<BenchScene> scenes = {
      threeBody("equal", "equal masses, 3 collisions", {{1, 1, 1}, {1.0371, 0, -1.5193}, {-1, 0, 1}}, true),
      threeBody("general_123", "masses (1, 2, 3)", {{1, 2, 3}, {1.0371, 0, -1.5193}, {-1, 0, 1}}, true),
      threeBody("pi_100", "pi billiard, wall, 100:1 (31)", {{100, 1, kInf}, {1.0371, 0.5193, 0}, {-1, 0, 0}}, true),
      threeBody("pi_1e6", "pi billiard, wall, 10^6:1 (3141)", {{1e6, 1, kInf}, {1.0371, 0.5193, 0}, {-1, 0, 0}},
                false),
      threeBody("heavy_light_heavy", "(1e6, 1, 1e6)", {{1e6, 1, 1e6}, {0.5371, 0, -0.4829}, {-1, 0, 0}}, false),
      threeBody("grazing", "grazing (3, 1, 0.5): last contact at speed 0",
                {{3, 1, 0.5}, {1.0371, 0, -0.9193}, {-1, 0, 0}}, true),
      // t_BC < t_AB by a few ulps: BC is first (3 collisions); naive double picks AB (2).
      threeBody("near_triple", "near-triple (1, 3, 1): BC first by ulps",
                {{1, 3, 1}, {0.9371, 0, -0.23427499999999998}, {-0.7, 0.1, 0.3}}, true),
      nBody("two_carts_e08", "two equal carts head on, e = 0.8: 1 impact, they part at 0.8 m/s each",
            {{1, 1}, {1.0371371, 0}, {-1, 1}, {0.8}}, 3.0, "two_carts_inelastic", 1),
      // Bounces at t_1 = 0.4628629 s and t_k = t_1 + sum_{j=1}^{k-1} 0.9^-j s: 4 before 5 s.
      nBody("ball_walls_e09", "a ball between two walls 1 m apart, e = 0.9: bounces forever; 4 before 5 s",
            {{kInf, 1, kInf}, {1, 0.5371371, 0}, {0, 1, 0}, {0.9}}, 5.0, "bouncing_ball_wall", 4,
            50),  // the preset's max_collisions
      nBody("cradle_5", "Newton's cradle with gaps, 5 equal masses: 4 impacts, the left one leaves at -1 m/s",
            {{1, 1, 1, 1, 1}, {3.9613371, 2.9371, 1.9193, 0.9627, 0}, {-1, 0, 0, 0, 0}, {}}, 5.0, "cradle_5", 4),
      nBody("near_collapse", "three equal masses, e = 0.072, just above r_c = 0.0718: 63 impacts",
            {{1, 1, 1}, {2.0371371, 1, 0}, {-1, 0, 0}, {0.072}}, 13.0, "near_collapse", 63),
      // From Python's random.Random(32): masses 0.5 + 1.5 u, velocities 2u - 1, gaps
      // 0.1 + 0.3 u, e 0.6 + 0.4 u (u uniform in [0, 1)), rounded to 3-4 decimals.
      nBody("random_10",
            "10 bodies, mixed masses, one e per pair (seeded): the exact event engine, no formula",
            {{0.616, 0.82, 0.955, 1.85, 1.244, 1.58, 0.65, 1.263, 1.765, 1.284},
             {1.7028, 1.3168, 1.1563, 1.0318, 0.8956, 0.5023, 0.3687, 0.2208, 0.1148, 0},
             {0.889, 0.764, -0.258, -0.999, 0.511, -0.747, -0.981, 0.461, 0.686, 0.673},
             {0.615, 0.741, 0.665, 0.724, 0.972, 0.667, 0.926, 0.895, 0.827}},
            3.5, "", std::nullopt),
  };
  return scenes;
}

struct Reference {
  std::uint64_t collision_count = 0;  ///< impacts up to end_time
  std::optional<std::size_t> first_pair;
  std::vector<double> velocities;        ///< at end_time [m/s]
  std::vector<double> positions_at_end;  ///< [m]
  double last_collision_time = 0.0;
  bool finished = false;  ///< no impact after end_time
  std::string check;      ///< how the independent checks agreed
};

/// exact::walkVelocityMaps, on the three-body scenes: count, first pair and velocities.
std::string crossCheckThreeBody(const BenchScene& s, Reference* ref) {
  const exact::MapWalk run = exact::walkVelocityMaps(*s.three, 10'000'000);
  std::vector<double> v(3);
  for (int i = 0; i < 3; ++i) v[i] = static_cast<double>(run.final_velocities[i]);
  const double diff = relativeVelocityError(s.scene.masses, ref->velocities, v);
  const bool agree = run.impact_count == ref->collision_count &&
                     run.first_pair == (ref->first_pair ? std::optional<Pair>(*ref->first_pair == 0 ? Pair::AB : Pair::BC)
                                                        : std::nullopt) &&
                     diff <= 4 * std::numeric_limits<double>::epsilon();
  ref->velocities = v;  // exact::walkVelocityMaps is the stated reference for velocities
  return agree ? "exact::walkVelocityMaps agrees (count, first pair, velocities to rounding)"
               : format("MISMATCH: exact::walkVelocityMaps count %llu, velocity difference %s",
                        static_cast<unsigned long long>(run.impact_count), sci(diff).c_str());
}

Reference makeReference(const BenchScene& s) {
  Reference ref;
  const ExactTrajectory trajectory(s.scene, 10'000'000, s.end_time);
  ref.collision_count = trajectory.impactCount();
  ref.first_pair = trajectory.firstPairIndex();
  ref.velocities = trajectory.finalVelocities();
  ref.positions_at_end = trajectory.positionsAt(s.end_time);
  ref.last_collision_time = trajectory.lastCollisionTime();
  ref.finished = trajectory.finished();
  bool ok = true;
  if (s.three) {
    ref.check = crossCheckThreeBody(s, &ref);
    ok = ref.check.rfind("MISMATCH", 0) != 0;
  } else if (s.known_count) {
    ok = *s.known_count == ref.collision_count;
    ref.check = ok ? format("the count %llu of %s agrees", static_cast<unsigned long long>(*s.known_count),
                            s.preset.empty() ? "physics.md" : ("the preset " + s.preset).c_str())
                   : format("MISMATCH: expected %llu", static_cast<unsigned long long>(*s.known_count));
  } else {
    ref.check = "no independent count (no formula exists)";
  }
  if (!ok) std::fprintf(stderr, "warning: %s: %s\n", s.name.c_str(), ref.check.c_str());
  return ref;
}
struct Row {
  std::string method;
  std::string scene;
  std::string parameter;
  double wall_time_s = NAN;
  int runs = 0;
  std::uint64_t collisions = 0;
  std::int64_t count_error = 0;
  double velocity_rel_error = NAN;
  double energy_rel_error = NAN;
  double position_abs_error = NAN;
  std::string note;  ///< non-empty: the method cannot answer this scene, and why (no numbers)
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

double maxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = std::fabs(a[i] - b[i]);
    if (std::isnan(d)) return NAN;
    worst = std::max(worst, d);
  }
  return worst;
}

Row noteRow(const std::string& method, const BenchScene& s, const std::string& parameter, std::string note) {
  Row row;
  row.method = method;
  row.scene = s.name;
  row.parameter = parameter;
  row.note = std::move(note);
  return row;
}

/// A row measured against the reference. Empty v: the method gives no velocities; empty
/// x_end: no positions.
Row makeRow(const std::string& method, const BenchScene& s, const std::string& parameter, const Reference& ref,
            double time, int runs, std::uint64_t collisions, const std::vector<double>& v,
            const std::vector<double>& x_end) {
  Row row = noteRow(method, s, parameter, "");
  row.wall_time_s = time;
  row.runs = runs;
  row.collisions = collisions;
  row.count_error = static_cast<std::int64_t>(collisions) - static_cast<std::int64_t>(ref.collision_count);
  const auto& m = s.scene.masses;
  if (!v.empty()) {
    row.velocity_rel_error = relativeVelocityError(m, v, ref.velocities);
    const long double e0 = kineticEnergy(m, s.scene.velocities);
    row.energy_rel_error = static_cast<double>(std::fabs(kineticEnergy(m, v) - kineticEnergy(m, ref.velocities)) / e0);
  }
  if (!x_end.empty()) row.position_abs_error = maxAbsDiff(x_end, ref.positions_at_end);
  return row;
}

Row runClosedForm(const BenchScene& s, const Reference& ref, bool quick) {
  std::uint64_t count = 0;
  std::vector<double> v(3);
  auto work = [&] {
    count = predictedImpactCount(*s.three);
    const AnalyticModel<double> model(*s.three);
    const auto after = model.velocitiesAfter(count);
    for (int i = 0; i < 3; ++i) v[i] = after[i];
  };
  int runs = 0;
  const double time = medianTime(work, quick, &runs);
  return makeRow("closed_form", s, "double", ref, time, runs, count, v, {});
}

Row runNbodyEngine(const BenchScene& s, const Reference& ref, bool quick) {
  EngineOptions options;
  options.max_impacts = s.engine_cap;
  // The state at end_time: the core's replay of the impacts up to it.
  BodyStateReplay state(s.scene);
  SceneSimulation result;
  auto work = [&] {
    state = BodyStateReplay(s.scene);
    result = runEngine(s.scene, options, [&](const ImpactRecord& r) {
      if (r.time <= s.end_time) state.apply(r);
    });
  };
  int runs = 0;
  const double time = medianTime(work, quick, &runs);
  if (!result.collapses.empty()) return noteRow("nbody_engine", s, "exact", "collapsed: state not rebuilt");
  return makeRow("nbody_engine", s, "exact", ref, time, runs, state.impacts(), state.velocities(),
                 state.positions(s.end_time));
}

/// The closed-form model of the scene (models.h), when it gives one: count and final
/// velocities, no positions.
std::optional<Row> runModel(const BenchScene& s, const Reference& ref, bool quick) {
  std::optional<Prediction> prediction;
  auto work = [&] { prediction = predict(s.scene); };
  int runs = 0;
  const double time = medianTime(work, quick, &runs);
  if (!prediction) return std::nullopt;
  const std::string kind = modelKindName(prediction->kind);
  if (prediction->infinite) return noteRow("model", s, kind, "infinitely many impacts: no state at t_end");
  if (!prediction->impact_count) return noteRow("model", s, kind, "no count: " + prediction->reason);
  return makeRow("model", s, kind, ref, time, runs, *prediction->impact_count, prediction->final_velocities, {});
}

Row runStepped(const SteppedMethod& method, double dt, const BenchScene& s, const Reference& ref, bool quick) {
  SteppedRun result;
  const StepConfig config{dt, s.end_time};
  auto work = [&] { result = method.run(s.scene, config); };
  int runs = 0;
  const double time = medianTime(work, quick, &runs);
  if (!result.unsupported.empty()) return noteRow(method.name, s, format("%g", dt), result.unsupported);
  return makeRow(method.name, s, format("%g", dt), ref, time, runs, result.collisions, result.velocities,
                 result.positions);
}

std::string csvNumber(double value) { return std::isnan(value) ? "nan" : format("%.6e", value); }

std::string toCsv(const std::vector<Row>& rows) {
  std::ostringstream out;
  out << "method,scene,parameter,wall_time_s,collisions,count_error,velocity_rel_error,"
         "energy_rel_error,position_abs_error,note\n";
  for (const auto& r : rows) {
    out << r.method << ',' << r.scene << ',' << r.parameter << ',';
    if (r.note.empty()) {
      out << csvNumber(r.wall_time_s) << ',' << r.collisions << ',' << r.count_error << ','
          << csvNumber(r.velocity_rel_error) << ',' << csvNumber(r.energy_rel_error) << ','
          << csvNumber(r.position_abs_error) << ",\n";
    } else {
      out << "nan,,,nan,nan,nan,\"" << r.note << "\"\n";
    }
  }
  return out.str();
}

bool isOurs(const std::string& method) {
  return method == "closed_form" || method == "nbody_engine" || method == "model";
}

/// Our method every stepping method is compared with: the event engine, which simulates
/// every scene.
std::string anchorOf(const BenchScene&) { return "nbody_engine"; }

const Row* findRow(const std::vector<Row>& rows, const std::string& scene, const std::string& method) {
  for (const auto& r : rows) {
    if (r.scene == scene && r.method == method && r.note.empty()) return &r;
  }
  return nullptr;
}

/// The "Done when" checks of issue 4, as measured.
std::string doneWhen(const std::vector<Row>& rows, const std::vector<BenchScene>& scenes,
                     const std::vector<SteppedMethod>& stepped) {
  std::ostringstream out;
  out << "## Checks (measured, not asserted)\n\n";
  int bad = 0;
  for (const auto& r : rows) {
    if (!isOurs(r.method) || !r.note.empty()) continue;
    const bool pos_ok = std::isnan(r.position_abs_error) ? (r.method == "closed_form" || r.method == "model")
                                                         : r.position_abs_error <= 1e-9;
    const bool vel_ok = std::isnan(r.velocity_rel_error) ? r.method == "model" : r.velocity_rel_error <= 1e-12;
    if (r.count_error != 0 || !vel_ok || !pos_ok) {
      ++bad;
      out << "- **Missed**: " << r.method << " on " << r.scene << ": count error " << r.count_error
          << ", velocity error " << sci(r.velocity_rel_error) << ", position error "
          << sci(r.position_abs_error) << ".\n";
    }
  }
  if (bad == 0) {
    out << "- Our exact methods: count error 0, velocity error <= 1e-12 and position error "
           "<= 1e-9 m on every scene (closed_form and model give no positions): **met**.\n";
  }
  const int engines = static_cast<int>(stepped.size()) - 1;
  out << "- Real engines measured: " << engines << " (goal at least 2: " << (engines >= 2 ? "**met**" : "**missed**")
      << ").\n";
  out << "- Cost for a stepping method to reach our accuracy on each scene (count error 0, "
         "velocity error <= max(1e-12, ours), position error <= max(1e-9 m, ours); ours = "
         "nbody_engine, the event engine that simulates every scene), as a multiple "
         "of our time (goal: >= 100x or never):\n\n";
  out << "| scene |";
  for (const auto& m : stepped) out << ' ' << m.name << " |";
  out << "\n|---|";
  for (std::size_t i = 0; i < stepped.size(); ++i) out << "---|";
  out << '\n';
  bool all_met = true;
  for (const auto& s : scenes) {
    const Row* ours = findRow(rows, s.name, anchorOf(s));
    if (!ours) continue;
    out << "| " << s.name << " |";
    for (const auto& m : stepped) {
      const Row* best = nullptr;
      bool any = false;
      for (const auto& r : rows) {
        if (r.scene != s.name || r.method != m.name || !r.note.empty()) continue;
        any = true;
        const bool reached = r.count_error == 0 &&
                             r.velocity_rel_error <= std::max(1e-12, ours->velocity_rel_error) &&
                             r.position_abs_error <= std::max(1e-9, ours->position_abs_error);
        if (reached && (!best || r.wall_time_s < best->wall_time_s)) best = &r;
      }
      if (!any) {
        out << " cannot represent it |";
      } else if (!best) {
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

/// One line per scene: our exact method against the most accurate trajectory each
/// stepping method reached (over its dt sweep, right count or not).
std::string summary(const std::vector<Row>& rows, const std::vector<BenchScene>& scenes,
                    const std::vector<Reference>& refs, const std::vector<SteppedMethod>& stepped) {
  std::ostringstream out;
  out << "## Summary\n\nOurs (nbody_engine: the event engine, which simulates every scene) against the smallest trajectory error each stepping method "
         "reached over its dt sweep: *position error [m] (count error) at dt, time*.\n\n"
      << "| scene | exact N | ours: method, time, velocity err, position err [m] |";
  for (const auto& m : stepped) out << " best " << m.name << " |";
  out << "\n|---|---|---|";
  for (std::size_t i = 0; i < stepped.size(); ++i) out << "---|";
  out << '\n';
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const auto& s = scenes[k];
    const Row* ours = findRow(rows, s.name, anchorOf(s));
    if (!ours) continue;
    out << "| " << s.name << " | " << refs[k].collision_count << " | "
        << format("%s, %s s, %s, %s", ours->method.c_str(), sci(ours->wall_time_s).c_str(),
                  sci(ours->velocity_rel_error).c_str(), sci(ours->position_abs_error).c_str())
        << " |";
    for (const auto& m : stepped) {
      const Row* best = nullptr;
      std::string note;
      for (const auto& r : rows) {
        if (r.scene != s.name || r.method != m.name) continue;
        if (!r.note.empty()) note = r.note;
        else if (!best || r.position_abs_error < best->position_abs_error) best = &r;
      }
      if (!best) {
        out << ' ' << (note.empty() ? "-" : note) << " |";
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

/// The shortest of %.15g, %.16g, %.17g that reads back as the same double; "inf" for walls.
std::string shortest(double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  for (int digits = 15; digits < 17; ++digits) {  // 15 digits: plain decimals, no exponent for 1e6
    const std::string text = format("%.*g", digits, value);
    if (std::strtod(text.c_str(), nullptr) == value) return text;
  }
  return format("%.17g", value);
}

std::string list(const std::vector<double>& values) {
  std::string out = "(";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + shortest(values[i]);
  return out + ")";
}

std::string scenesTable(const std::vector<BenchScene>& scenes, const std::vector<Reference>& refs) {
  std::ostringstream out;
  out << "## Scenes\n\n| scene | what | preset | masses [kg] | positions [m] | velocities [m/s] | e | t_end [s] | "
         "exact impacts before t_end | first pair | last impact [s] | reference check |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const auto& s = scenes[i];
    const auto& ref = refs[i];
    out << "| " << s.name << " | " << s.description << " | " << (s.preset.empty() ? "-" : s.preset) << " | "
        << list(s.scene.masses) << " | " << list(s.scene.positions) << " | " << list(s.scene.velocities) << " | "
        << (s.scene.restitution.empty() ? "1" : list(s.scene.restitution)) << " | " << shortest(s.end_time) << " | "
        << ref.collision_count << (ref.finished ? "" : " (more after)") << " | "
        << (ref.first_pair ? pairName(*ref.first_pair) : "-") << " | " << format("%.6f", ref.last_collision_time)
        << " | " << ref.check << " |\n";
  }
  out << "\nA wall (mass inf) is a static sphere in Bullet, a plane in ODE and a static circle in Box2D. "
         "Preset: the scene of config/scenarios.yaml with the same masses, velocities and e "
         "(positions moved off the dt grid, see above).\n\n";
  return out.str();
}

std::string resultsTables(const std::vector<Row>& rows, const std::vector<BenchScene>& scenes) {
  std::ostringstream out;
  out << "## Results\n\n";
  for (const auto& s : scenes) {
    out << "### " << s.name << "\n\n| method | parameter | wall_time_s | runs | collisions | count_error | "
           "velocity_rel_error | energy_rel_error | position_abs_error [m] |\n"
           "|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : rows) {
      if (r.scene != s.name) continue;
      if (!r.note.empty()) {
        out << "| " << r.method << " | " << r.parameter << " | " << r.note << " | | | | | | |\n";
        continue;
      }
      out << "| " << r.method << " | " << r.parameter << " | " << sci(r.wall_time_s) << " | " << r.runs
          << " | " << r.collisions << " | " << r.count_error << " | " << sci(r.velocity_rel_error) << " | "
          << sci(r.energy_rel_error) << " | "
          << (std::isnan(r.position_abs_error) ? std::string("n/a") : sci(r.position_abs_error)) << " |\n";
    }
    out << '\n';
  }
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
      << "Every scene runs from t = 0 to its t_end (3 s for the three-body scenes), after its last "
         "exact impact (the ball between two walls bounces forever: its t_end falls between two "
         "bounces), and every method is compared with the exact reference at that instant.\n\n"
      << "- **wall_time_s**: median wall time of one run [s] (runs column: how many runs "
         "the median is over; sub-millisecond runs are timed in batches). This machine is "
         "shared (" << std::thread::hardware_concurrency() << " hardware threads); read ratios, not absolutes.\n"
      << "- **count_error**: impacts counted up to t_end minus the exact count. Stepping methods count "
         "a collision when a pair goes from approaching to not approaching between two steps.\n"
      << "- **velocity_rel_error**: max_i |v_i - v_i,exact| / max_i |v_i,exact| at t_end, "
         "finite masses only.\n"
      << "- **energy_rel_error**: |E_end - E_end,exact| / E_0, kinetic energy of the finite masses "
         "(for elastic scenes E_end,exact = E_0: the energy drift).\n"
      << "- **position_abs_error**: max_i |x_i(t_end) - x_i,exact| [m], the trajectory error. "
         "closed_form and model give velocities and the count, not positions (n/a).\n"
      << "- A row whose wall_time_s column holds a sentence: the method cannot answer that scene, and why.\n\n"
      << "Reference: an exact GMP rational trajectory (bench/common/exact_trajectory.cpp, N bodies, "
         "walls, each e the exact value of its double), written independently of the core; positions "
         "and velocities rounded to double. On the three-body scenes the count and velocities come from "
         "`exact::walkVelocityMaps` (Boost cpp_rational), checked against it; on the others the count is checked "
         "against physics.md or the preset where one is known.\n\n";
  out << scenesTable(scenes, refs);
  out << "## Methods and every setting\n\n"
      << "- The three-body loop `simulate(scene, options, Precision)` (event_double, event_long_double, "
         "event_high) was removed with `--precision`: the event engine (nbody_engine below) simulates "
         "every scene.\n"
      << "- **closed_form** (three-body scenes): `predictedImpactCount(scene)`, then "
         "`AnalyticModel<double>(scene).velocitiesAfter(count)`; the time includes both.\n"
      << "- **nbody_engine** (every scene): the exact N-body engine, `runEngine(scene, options, visitor)` "
         "(include/collision_lab/core/nbody/engine.h), max_impacts 10^7 (ball_walls_e09: 50, the preset's "
         "cap); the visitor rebuilds the state at t_end from the impact records with the core's replay, "
         "`core::BodyStateReplay` (each body's contact "
         "position, time and velocity after its last impact at or before t_end); the time includes it.\n"
      << "- **model** (N-body and restitution scenes): `predict(scene)` (models.h), the closed-form model "
         "chosen for the scene (parameter column): its count and final velocities, no positions.\n";
  for (const auto& m : stepped) out << "- **" << m.name << "**: " << m.settings << "\n";
  out << "\nAll engines use spheres (circles) of radius " << kEngineRadius
      << " m; centres are shifted by the radii (body i of N by (N - 1 - 2i) r: A by +2r and C by -2r "
         "for three bodies) so bodies touch exactly when the point masses would, and shifted back when read.\n\n";
  out << summary(rows, scenes, refs, stepped);
  out << doneWhen(rows, scenes, stepped);
  out << resultsTables(rows, scenes);
  return out.str();
}

/// The issue-13 goal: every N-body or restitution scene measured by the fixed-step loop
/// and every real engine, and answered exactly by ours.
std::string goalLine(const std::vector<Row>& rows, const std::vector<BenchScene>& scenes,
                     const std::vector<SteppedMethod>& stepped) {
  int covered = 0, total = 0;
  for (const auto& s : scenes) {
    if (s.three) continue;
    ++total;
    bool all = true;
    for (const auto& m : stepped) all = all && findRow(rows, s.name, m.name) != nullptr;
    const Row* ours = findRow(rows, s.name, "nbody_engine");
    all = all && ours && ours->count_error == 0 && ours->position_abs_error <= 1e-9;
    covered += all;
  }
  std::string names;
  for (const auto& m : stepped) names += (names.empty() ? "" : ", ") + m.name;
  return format("goal: speed-vs-error report covers N-body and restitution scenes with %s = %d of %d scenes, "
                "%zu stepping methods, nbody_engine exact on each (goal: every scene, fixed_step + 3 engines): %s\n",
                names.c_str(), covered, total, stepped.size(),
                covered == total && total > 0 && stepped.size() >= 4 ? "met" : "missed");
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
  // The N-body and restitution scenes run longer with more bodies: real engines stop at 1e-5 s.
  const std::vector<double> dts_engine_nbody =
      quick ? std::vector<double>{1e-2, 1e-3, 1e-4} : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5};

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
    auto add = [&](const Row& r) {
      rows.push_back(r);
      std::fprintf(stderr, "[%s] %-18s %-10s %10.3e s  count error %+lld  pos error %s %s (%.0f s total)\n",
                   s.name.c_str(), r.method.c_str(), r.parameter.c_str(), r.wall_time_s,
                   static_cast<long long>(r.count_error), sci(r.position_abs_error).c_str(), r.note.c_str(),
                   total.seconds());
    };
    if (s.three) {
      add(runClosedForm(s, ref, quick));
    }
    add(runNbodyEngine(s, ref, quick));
    if (!s.three) {
      if (auto model = runModel(s, ref, quick)) add(*model);
    }
    for (const auto& method : stepped) {
      const auto& dts = method.name == "fixed_step" ? dts_fixed : s.three ? dts_engine : dts_engine_nbody;
      for (double dt : dts) add(runStepped(method, dt, s, ref, quick));
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
  std::fputs(goalLine(rows, scenes, stepped).c_str(), stdout);
  std::fprintf(stderr, "done in %.1f s\n", total.seconds());
  return ok ? 0 : 1;
}
