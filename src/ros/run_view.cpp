#include "collision_lab/ros/run_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "collision_lab/core/nbody/scene.h"
#include "collision_lab/core/nbody/temperature.h"
#include "collision_lab/ros/view_style.h"

namespace collision_lab_ros {

using collision_lab::InitialConditions;
using collision_lab::Prediction;
using markers::format;
using markers::withSeparators;

namespace {

bool notSimulated(const RunRecord& run) {
  return run.input().mode == InitialConditions::MODE_PREDICT_ONLY || (run.summary && !run.summary->simulated);
}

/// Many bodies, inelastic: a granular gas (in a box, on a ring or free), with a T(t) view.
bool isGas(const RunRecord& run) {
  const auto& e = run.input().restitution;
  const bool inelastic = std::any_of(e.begin(), e.end(), [](double r) { return r < 1.0; });
  return run.bodies() > kMaxPlottedBodies && inelastic;
}

std::string kindOf(const RunRecord& run) {
  if (run.input().ring > 0) return "ring";
  const std::size_t n = run.bodies();
  if (n >= 3 && run.isWall(0) && run.isWall(n - 1) && n > 3) return "box";
  if (isGas(run)) return "gas";
  return n == 3 ? "three_body" : "line";
}

/// "A..C" for bodies first .. last.
std::string bodyRange(std::size_t first, std::size_t last) {
  if (first == last) return "body " + collision_lab::core::bodyName(first);
  return "bodies " + collision_lab::core::bodyName(first) + ".." + collision_lab::core::bodyName(last);
}

std::string titleOf(const RunRecord& run) {
  std::string title = "run " + run.input().run_id;
  if (run.bodies() != 3) title += ",  " + withSeparators(run.bodies()) + " bodies";
  if (run.prediction) {
    const auto& p = *run.prediction;
    // Every prediction names its model; one with the paper's values (the rotation model's)
    // shows the paper's count as well.
    const bool paper_values = p.max_possible_collision_count > 0;
    title += " (" + p.model_name + ")";
    if (p.collapsed) {
      title += ":  predicted collapse at t = " + numberText(p.collapse_time, 6) + " s";
    } else if (p.infinite_collisions) {
      title += ":  predicted: infinitely many collisions";
    } else if (p.collision_count_defined) {
      title += ":  predicted " + collisionsText(p.collision_count);
    }
    if (paper_values) {
      title += p.paper_collision_count_defined
                   ? "  (paper's eq. 3.22: " + withSeparators(p.paper_collision_count) + ")"
                   : "  (paper's eq. 3.22: undefined)";
    }
  }
  if (run.summary) {
    title += run.summary->simulated ? ",  simulated " + withSeparators(run.summary->collision_count)
                                    : ",  not simulated";
    if (run.summary->truncated) title += " (truncated)";
    if (run.summary->collapse_count > 0) {
      title += " + " + withSeparators(run.summary->collapse_count) +
               (run.summary->collapse_count == 1 ? " collapse" : " collapses");
    }
  }
  return title;
}

/// One sentence for a run cut short: "stopped at the cap ...", never twice "truncated".
std::string truncationSentence(const std::string& reason) {
  std::string s = reason;
  const std::string marker = " (truncated)";  // the summary's own word: the view says it once
  for (auto at = s.find(marker); at != std::string::npos; at = s.find(marker)) s.erase(at, marker.size());
  while (!s.empty() && (s.back() == '.' || s.back() == ' ')) s.pop_back();
  if (s.rfind("stopped", 0) != 0) s = "stopped: " + s;
  return s + ".";
}

/// Collapse or not, for three bodies with e < 1: the restitution against the critical one
/// (Prediction.critical_restitution), so that a collapse and a near miss, whose final
/// velocities can round to the same doubles, are told apart.
std::string spiralFact(const RunRecord& run, const RunView& view) {
  if (!run.prediction || run.prediction->model_name != "three_body_spiral") return "";
  const double critical = run.prediction->critical_restitution;
  const auto& e = run.input().restitution;
  if (!std::isfinite(critical) || e.empty()) return "";
  const double least = *std::min_element(e.begin(), e.end());
  const std::string compared = "e = " + numberText(least, 6) + " is " +
                               (least <= critical ? "at most" : "above") + " the critical restitution r_c = " +
                               numberText(critical, 6);
  // The model's answer decides; e against r_c says why (e = 0 sticks, and a start that
  // separates ends the walk, below r_c too).
  if (run.prediction->collapsed) {
    return "collapse: " + compared + ": infinitely many collisions in a finite time, then the three move as one";
  }
  if (!view.predicted_collisions) return "";
  std::string fact = "no collapse: after " + collisionsText(*view.predicted_collisions) + " the bodies move apart";
  if (least > critical) fact += " (" + compared + ")";
  const auto& v = run.prediction->final_velocities;
  if (v.size() == 3 && v[0] == v[1] && v[1] == v[2]) fact += ", more slowly than the digits shown can tell";
  return fact;
}

std::string noteOf(const RunRecord& run, const RunView& view) {
  std::string note;
  if (run.missedCollisions() > 0) {
    note += withSeparators(run.missedCollisions()) + " collision messages missing; ";
  }
  // Past ~max_published_events the web node gets sampled states (RunProgress) only.
  const std::string sampled = "the plots are sampled past the first " + collisionsText(run.sampledAfter()) + " published";
  if (run.sampled() && run.summary) note += sampled + " (the run has no bag to draw every collision from); ";
  if (!view.truncated.empty()) {
    note += view.truncated + " Shown up to the last known state.";
  } else if (run.input().mode == InitialConditions::MODE_PREDICT_ONLY) {
    note += "predict-only run, no collision simulated (an animation stops at the first contact): the final "
            "velocities shown are the closed form's.";
  } else if (run.summary && !run.summary->simulated) {
    note += "answered by the model (more collisions predicted than the cap), no collision simulated (an animation "
            "stops at the first contact): the final velocities shown are the closed form's.";
  } else if (run.input().mode == InitialConditions::MODE_SUMMARY_ONLY) {
    note += "summary-only run: shown up to the first contact; the plots show the final velocities.";
  } else if (!run.finished()) {
    note += run.sampled() ? "run in progress: " + sampled + "; the whole run is drawn from its bag when it ends."
                          : "run in progress: shown up to the last collision received.";
  }
  return note;
}

std::vector<ViewBody> viewBodies(const std::vector<std::size_t>& indices, const RunView& view) {
  std::vector<ViewBody> out;
  for (std::size_t i : indices) out.push_back({i, collision_lab::core::bodyName(i), view.body_colours.at(i)});
  return out;
}

std::string hexOf(double r, double g, double b) {
  auto byte = [](double v) { return static_cast<unsigned>(std::lround(std::clamp(v, 0.0, 1.0) * 255)); };
  char buffer[8];
  std::snprintf(buffer, sizeof buffer, "#%02x%02x%02x", byte(r), byte(g), byte(b));
  return buffer;
}

/// RunView's colours (see RunView::body_colours): the palette by index while it has a
/// colour for every body, else the start velocity's on a diverging map; walls grey.
void decideColours(const RunRecord& run, RunView& view) {
  namespace layout = markers::layout;
  const std::size_t n = run.bodies();
  view.colour_by_start_velocity = n > layout::kPaletteSize;
  if (view.colour_by_start_velocity) view.colour_scale = markers::velocityScale(run);
  for (std::size_t i = 0; i < n; ++i) {
    if (run.isWall(i)) {
      view.body_colours.push_back(hexOf(layout::kGrey.r, layout::kGrey.g, layout::kGrey.b));
    } else if (view.colour_by_start_velocity) {
      // Each channel as rviz gets it (a float of std_msgs/ColorRGBA), so that both draw one colour.
      const auto c = markers::velocityRgb(run.input().velocities[i], view.colour_scale);
      view.body_colours.push_back(hexOf(static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b)));
    } else {
      view.body_colours.push_back(bodyColourHex(i));
    }
  }
  if (view.colour_by_start_velocity) {
    const std::string v = numberText(view.colour_scale);
    view.colour_legend = "colour: velocity at the start, blue: moving left (deepest at -" + v +
                         " m/s), purple: at rest, red: moving right (deepest at +" + v + " m/s)";
  }
}

/// "all 3 bodies" or "24 of 1,002 bodies, evenly spaced, the outermost two included".
std::string legendOf(std::size_t shown, std::size_t all) {
  if (shown == 0) return "no single bodies: the plot shows sums over all " + withSeparators(all) + " bodies";
  if (shown >= all) return all == 1 ? "the only body" : "all " + withSeparators(all) + " bodies";
  return withSeparators(shown) + " of " + withSeparators(all) + " bodies, evenly spaced, the outermost two included";
}

/// The cap that stopped a run the model answered over its cap: the input's max_collisions,
/// or the lab's ~max_collisions when the input asked for none (0) or for more than the
/// prediction (the lab's ceiling, lower, applied).
std::string appliedCapText(std::uint64_t asked, const std::optional<std::uint64_t>& predicted) {
  if (asked == 0) return "this lab's cap (its ~max_collisions)";
  if (predicted && *predicted <= asked) {
    return "this lab's cap (its ~max_collisions, below the " + withSeparators(asked) + " asked for)";
  }
  return "the cap of " + withSeparators(asked);
}

/// What a class can do about a run the model answered instead of the engine because of its
/// cap.
std::string howToSimulate(const collision_lab::InitialConditions& in, const RunView& view) {
  if (view.infinitely_many_predicted) {
    return ". Infinitely many collisions cannot all be simulated; the lab simulates the first ones, up to the cap, "
           "when its ~simulate_to_cap is on: ask the teacher";
  }
  if (!view.predicted_collisions) return "";
  const std::string count = withSeparators(*view.predicted_collisions);
  if (in.max_collisions != 0 && *view.predicted_collisions > in.max_collisions) {
    return ". To simulate it, set \"Stop after\" (max_collisions) to at least " + count;
  }
  return ". To simulate it, the lab's ~max_collisions must allow " + count + " collisions: ask the teacher";
}

}  // namespace

std::string collisionsText(std::uint64_t n) {
  return withSeparators(n) + (n == 1 ? " collision" : " collisions");
}

std::string bodyColourHex(std::size_t i) {
  const auto& c = markers::layout::kParticleRgb[i % markers::layout::kPaletteSize];
  return hexOf(c.r, c.g, c.b);
}

std::string numberText(double value, int significant_digits) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.*g", significant_digits, value);
  const std::string text = buffer;
  const auto e = text.find('e');
  if (e == std::string::npos) return text;
  return text.substr(0, e) + "×10^" + std::to_string(std::stoi(text.substr(e + 1)));
}

RunView makeRunView(const RunRecord& run) {
  RunView view;
  const auto& in = run.input();
  view.kind = kindOf(run);
  view.simulated = in.mode == InitialConditions::MODE_FULL && !notSimulated(run);

  if (run.summary && run.summary->simulated) view.simulated_collisions = run.summary->collision_count;
  else if (!notSimulated(run)) view.simulated_collisions = run.collisions();
  if (run.prediction && run.prediction->collision_count_defined && !run.prediction->infinite_collisions) {
    view.predicted_collisions = run.prediction->collision_count;
  } else if (run.summary && run.summary->predicted_collision_count_defined && !run.summary->infinite_collisions) {
    view.predicted_collisions = run.summary->predicted_collision_count;
  }
  view.infinitely_many_predicted = (run.prediction && run.prediction->infinite_collisions) ||
                                   (run.summary && run.summary->infinite_collisions);

  if (notSimulated(run)) {
    std::string why;
    if (in.mode == InitialConditions::MODE_PREDICT_ONLY) {
      why = "predict-only run, the model answered";
    } else if (run.summary && !run.summary->truncation_reason.empty()) {
      why = run.summary->truncation_reason;
    } else {
      why = "more collisions predicted than " + appliedCapText(in.max_collisions, view.predicted_collisions) +
            ", the model answered" + howToSimulate(in, view);
    }
    while (!why.empty() && why.back() == '.') why.pop_back();
    view.not_simulated = "not simulated: " + why;
  } else if (run.summary && run.summary->truncated) {
    view.truncated = truncationSentence(run.summary->truncation_reason);
  }

  // The collapses: those received as events, else the summary's or the model's one.
  std::vector<RunRecord::CollapseMark> marks = run.namedCollapses();
  view.collapse_count = std::max<std::uint64_t>(run.collapses(), run.summary ? run.summary->collapse_count : 0);
  if (marks.empty() && ((run.summary && run.summary->collapsed) || (run.prediction && run.prediction->collapsed))) {
    RunRecord::CollapseMark whole;
    whole.bodies = {0, run.bodies() ? run.bodies() - 1 : 0};
    const bool simulated = run.summary && run.summary->collapsed;
    whole.time = simulated ? run.summary->collapse_time : run.prediction->collapse_time;
    whole.position = simulated ? run.summary->collapse_position : run.prediction->collapse_position;
    marks.push_back(whole);
  }
  if (!marks.empty()) {
    view.collapse_count = std::max<std::uint64_t>(view.collapse_count, marks.size());
    view.collapse_time = marks.front().time;
    view.collapse_position = marks.front().position;
    for (std::size_t k = 0; k < marks.size(); ++k) {
      const RunRecord::CollapseMark& mark = marks[k];
      view.collapse += (k == 0 ? "collapse" : "; collapse " + std::to_string(k + 1)) + " at t = " +
                       format("%.6g s", mark.time) + ", x = " + format("%.6g m", mark.position) + ", " +
                       bodyRange(mark.bodies.first, mark.bodies.second);
    }
    if (view.collapse_count > marks.size()) {
      view.collapse += "; and " + withSeparators(view.collapse_count - marks.size()) + " more";
    }
    view.collapse_brief = view.collapse.substr(0, view.collapse.find(';'));
    if (view.collapse_count > 1) {
      view.collapse_brief += "; " + withSeparators(view.collapse_count - 1) + " more";
    }
  }

  if (in.ring > 0) {
    view.ring_circumference = in.ring;
    view.ring = "ring of " + (in.ring == std::floor(in.ring) && in.ring < 1e15
                                  ? withSeparators(static_cast<std::uint64_t>(in.ring))
                                  : format("%.6g", in.ring)) +
                " m";
  }
  if (view.kind == "box") view.box = "box: walls at both ends";
  view.spiral = spiralFact(run, view);
  for (std::size_t i = 0; i < in.masses.size() && i < in.velocities.size(); ++i) {
    if (!std::isfinite(in.masses[i]) && in.velocities[i] != 0.0) {
      view.moving_wall =
          "a wall moves: a body that hits it gains or loses kinetic energy, the work the wall does, heat aside";
    }
  }

  view.collisions_so_far = run.collisions();
  if (run.summary && run.summary->simulated && !run.summary->truncated) {
    view.expected = run.summary->collision_count;
  } else if (view.predicted_collisions) {
    view.expected = std::max<std::uint64_t>(*view.predicted_collisions, run.collisions());
  }
  if (!view.not_simulated.empty()) view.state = "not simulated";
  else if (!view.truncated.empty()) view.state = "truncated";
  else if (run.summary) view.state = "finished";
  else view.state = "running";
  if (!view.not_simulated.empty()) {
    view.counter = view.not_simulated;
    if (view.predicted_collisions) view.counter += "; predicted " + collisionsText(*view.predicted_collisions);
    else if (view.infinitely_many_predicted) view.counter += "; predicted infinitely many collisions";
  } else {
    const std::uint64_t shown = view.simulated_collisions.value_or(run.collisions());
    view.counter = collisionsText(shown);
    if (view.state == "running") {
      view.counter = withSeparators(run.collisions()) + " collisions so far";
      if (view.expected && *view.expected > run.collisions()) {
        view.counter = withSeparators(run.collisions()) + " of " + collisionsText(*view.expected) + " predicted";
      } else if (view.infinitely_many_predicted) {
        view.counter += " (infinitely many predicted)";
      }
    }
    if (view.collapse_count > 0 && view.state != "running") {
      view.counter += " + " + withSeparators(view.collapse_count) + (view.collapse_count == 1 ? " collapse" : " collapses");
    }
    view.counter += ", " + view.state;
  }

  decideColours(run, view);
  view.worldline_bodies = viewBodies(run.trackedBodies(), view);
  const bool per_body = !run.plottedBodies().empty();
  view.velocity_bodies = viewBodies(per_body ? run.plottedBodies() : run.trackedBodies(), view);
  view.worldline_legend = legendOf(run.trackedBodies().size(), run.bodies());
  view.velocity_legend = legendOf(view.velocity_bodies.size(), run.bodies());

  view.end_time = endTime(run);
  view.gas = isGas(run);
  if (view.gas) {
    const auto samples = run.temperature();
    for (const auto& sample : samples) view.temperature.emplace_back(sample.time, sample.temperature);
    const auto fit = collision_lab::core::fitHaff(run.temperatureForFit());  // the CLI's fit
    view.haff_ok = fit.ok && std::isfinite(fit.tau);
    view.haff_t0 = fit.t0;
    view.haff_tau = fit.tau;
    // What T is, in a student's words, is the page's caption; this says what the lines are.
    // No subscript digits: rviz's font has code points below 1000 only (tau and the square do).
    // How well it fits (the rms of ln T's misfit: 0.1 is about 10%), and whether the run
    // saw a time as long as tau (else tau is an extrapolation of the early cooling).
    const double seen = samples.empty() ? 0.0 : samples.back().time;
    view.temperature_legend =
        view.haff_ok ? "Haff's law T = T0 / (1 + t/τ)² fitted: T0 = " + numberText(fit.t0) + " J, τ = " +
                           numberText(fit.tau) + " s"
                     : std::string("Haff's law: no fit (no cooling seen)");
    if (view.haff_ok) {
      view.temperature_fit_note = "How well it fits: the rms misfit of ln T is " + numberText(fit.rms_log_error, 2) +
                                  " (0.1: about 10%)" +
                                  (seen < fit.tau ? "; the run spans " + numberText(seen) +
                                                        " s, less than τ: τ extrapolates its early cooling"
                                                  : "") +
                                  ". Haff's law holds for a homogeneous gas cooling with a constant e.";
    }
    // T held from the last collision to the run's end: no collision changes it in the free
    // flight after it (the fit above is to the collisions' values only).
    if (!view.temperature.empty() && std::isfinite(view.end_time) && view.end_time > view.temperature.back().first) {
      view.temperature.emplace_back(view.end_time, view.temperature.back().second);
    }
  }

  view.title = titleOf(run);
  view.note = noteOf(run, view);
  return view;
}

std::vector<WorldlineSegments> worldlineSegments(const RunRecord& run, double end_time) {
  const double ring = run.input().ring;
  auto wrap = [ring](double x) {
    if (!(ring > 0)) return x;
    const double w = std::fmod(x, ring);
    return w < 0 ? w + ring : w;
  };
  const auto& frames = run.keyframes();
  std::vector<WorldlineSegments> out;
  for (std::size_t i : run.trackedBodies()) {
    WorldlineSegments line{i, {{}}};
    auto add = [&](double t, double x) {
      auto& segment = line.segments.back();
      if (!segment.empty() && ring > 0) {
        const auto [t0, x0] = segment.back();
        if (std::abs(x - x0) > ring / 2) {  // crossed the seam: cut there
          const bool rightwards = x < x0;
          const double dx = rightwards ? x + ring - x0 : x - ring - x0;
          const double at = t0 + (rightwards ? ring - x0 : -x0) / dx * (t - t0);
          segment.emplace_back(at, rightwards ? ring : 0.0);
          line.segments.push_back({{at, rightwards ? 0.0 : ring}});
        }
      }
      line.segments.back().emplace_back(t, x);
    };
    for (const auto& v : run.worldline(i).polyline()) add(v.x, wrap(v.y));
    // Free flight from the newest state (the initial one before any collision) to the run's
    // end, every seam crossing on the way.
    const bool started = !frames.empty();
    const std::vector<double>& positions = started ? frames.back().positions : run.input().positions;
    const std::vector<double>& velocities = started ? frames.back().velocities : run.input().velocities;
    if (i < positions.size() && i < velocities.size() && std::isfinite(end_time)) {
      double t = started ? frames.back().time : 0.0, x = positions[i];
      const double v = velocities[i];
      if (line.segments.back().empty() || line.segments.back().back().first < t) add(t, wrap(x));
      if (ring > 0 && v != 0 && std::isfinite(v)) {
        x = wrap(x);
        while (t < end_time) {
          const double to_seam = (v > 0 ? ring - x : -x) / v;
          if (t + to_seam >= end_time) break;
          t += to_seam;
          line.segments.back().emplace_back(t, v > 0 ? ring : 0.0);
          x = v > 0 ? 0.0 : ring;
          line.segments.push_back({{t, x}});
          if (line.segments.size() > 10000) break;  // a bound on the lines of one body
        }
        line.segments.back().emplace_back(end_time, wrap(x + v * (end_time - t)));
      } else if (end_time > t && std::isfinite(v)) {
        line.segments.back().emplace_back(end_time, x + v * (end_time - t));
      }
    }
    out.push_back(std::move(line));
  }
  return out;
}

nlohmann::json viewJson(const RunView& view) {
  auto bodies = [](const std::vector<ViewBody>& list) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& b : list) out.push_back({{"index", b.index}, {"name", b.name}, {"colour", b.colour}});
    return out;
  };
  auto optional = [](const std::optional<std::uint64_t>& n) { return n ? nlohmann::json(*n) : nlohmann::json(nullptr); };
  return {{"kind", view.kind},
          {"title", view.title},
          {"note", view.note},
          {"simulated", view.simulated},
          {"simulated_collisions", optional(view.simulated_collisions)},
          {"predicted_collisions", optional(view.predicted_collisions)},
          {"infinitely_many_predicted", view.infinitely_many_predicted},
          {"not_simulated", view.not_simulated},
          {"truncated", view.truncated},
          {"collapse", view.collapse},
          {"collapse_count", view.collapse_count},
          {"collapse_time", view.collapse.empty() ? nlohmann::json(nullptr) : nlohmann::json(view.collapse_time)},
          {"collapse_position",
           view.collapse.empty() || !std::isfinite(view.collapse_position) ? nlohmann::json(nullptr)
                                                                          : nlohmann::json(view.collapse_position)},
          {"ring", view.ring},
          {"ring_circumference", view.ring_circumference},
          {"box", view.box},
          {"moving_wall", view.moving_wall},
          {"spiral", view.spiral},
          {"collisions_so_far", view.collisions_so_far},
          {"expected_collisions", optional(view.expected)},
          {"state", view.state},
          {"counter", view.counter},
          {"worldline_bodies", bodies(view.worldline_bodies)},
          {"worldline_legend", view.worldline_legend},
          {"velocity_bodies", bodies(view.velocity_bodies)},
          {"velocity_legend", view.velocity_legend},
          {"colour_by_start_velocity", view.colour_by_start_velocity},
          {"colour_scale", view.colour_scale},
          {"body_colours", view.body_colours},
          {"colour_legend", view.colour_legend},
          {"gas", view.gas},
          {"temperature", [&] {
             nlohmann::json points = nlohmann::json::array();
             for (const auto& [t, T] : view.temperature) points.push_back({t, T});
             return points;
           }()},
          {"temperature_fit_note", view.temperature_fit_note},
          {"haff", view.haff_ok ? nlohmann::json{{"t0", view.haff_t0}, {"tau", view.haff_tau}} : nlohmann::json(nullptr)},
          {"temperature_legend", view.temperature_legend},
          {"end_time", std::isfinite(view.end_time) ? nlohmann::json(view.end_time) : nlohmann::json(nullptr)}};
}

}  // namespace collision_lab_ros
