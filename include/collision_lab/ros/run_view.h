// One description of a run's views, computed once from a RunRecord for rviz and for the
// class page (the web node's run JSON, part "view"): what was simulated, what the model
// answered, what was not simulated and why, the scene's kind, the counter, and which bodies
// each plot shows, with their names (core::bodyName) and colours (rviz's palette). rviz's
// title, note and status line and the page's texts are these texts: neither decides alone.
// Uses only what a RunRecord has without keyframes (the web node keeps none): its input,
// prediction, summary, counts and envelopes.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "collision_lab/ros/run_record.h"

namespace collision_lab_ros {

/// A body a plot shows: its index in masses[], its name and its colour.
struct ViewBody {
  std::size_t index = 0;
  std::string name;    ///< "A", "B", ... (core::bodyName)
  std::string colour;  ///< "#rrggbb", RunView::body_colours[index]: what rviz draws for it
};

struct RunView {
  /// "ring", "box", "gas" (many bodies, inelastic, no walls), "three_body" or "line".
  std::string kind;
  /// Many bodies, inelastic (in a box, on a ring or free): the T(t) view below is filled.
  bool gas = false;
  std::string title;  ///< rviz's title line
  std::string note;   ///< rviz's note: how the run ended or why it is not drawn whole ("" when none)

  /// True when collisions were simulated one by one and published (mode full, simulated).
  bool simulated = false;
  /// Simulated collisions [1]; empty when the run was not simulated.
  std::optional<std::uint64_t> simulated_collisions;
  /// Collisions the model predicted [1]; empty when it has no finite count.
  std::optional<std::uint64_t> predicted_collisions;
  bool infinitely_many_predicted = false;
  /// "" or "not simulated: <why>".
  std::string not_simulated;
  /// "" or one sentence: "stopped at the cap of 10 collisions."
  std::string truncated;

  /// The collapses: each named with its time, point and bodies, in order (the first
  /// RunRecord::kNamedCollapses; "" when none).
  std::string collapse;
  /// The first collapse alone, and how many more: for one line (rviz's status line).
  std::string collapse_brief;
  double collapse_time = 0.0;      ///< the first's [s]
  double collapse_position = 0.0;  ///< the first's [m]
  std::uint64_t collapse_count = 0;  ///< [1]

  /// "ring of 1,000 m" ("" when not a ring), its circumference [m] (0 when none).
  std::string ring;
  double ring_circumference = 0.0;
  /// Three bodies with e < 1 (the spiral model): collapse or not, against the critical
  /// restitution, in words ("" otherwise).
  std::string spiral;
  /// "a moving wall does work ..." when a wall moves ("" otherwise).
  std::string moving_wall;
  /// "box: walls at both ends" ("" when not a box).
  std::string box;

  /// The counter: collisions so far and expected, with the state word.
  std::uint64_t collisions_so_far = 0;        ///< [1]
  std::optional<std::uint64_t> expected;      ///< [1]; empty when unknown or infinite
  std::string state;                           ///< "running", "finished", "not simulated", "truncated"
  std::string counter;                         ///< e.g. "31 collisions, finished"

  /// One colour per body, decided here for every view (rviz draws these bytes exactly,
  /// r/255; the page these hexes): while rviz's palette has a colour for every body of the
  /// scene (at most layout::kPaletteSize bodies), body i has palette colour i (A red, B green,
  /// C blue, ...); beyond that, its velocity at the start on a diverging map (blue: moving
  /// left at colour_scale or faster, purple: at rest, red: moving right at colour_scale), so
  /// that no two bodies far apart share a colour by their index. Walls are grey either way.
  bool colour_by_start_velocity = false;
  double colour_scale = 0.0;  ///< [m/s] the map's ends: the start's largest |v| (0 with the palette)
  std::vector<std::string> body_colours;  ///< "#rrggbb" of body i, one per body of the scene
  /// What the colours mean, as rviz and the page both say it ("" with the palette: each body
  /// is named in its colour where it is drawn).
  std::string colour_legend;

  /// Bodies with a worldline on the x-t diagram and with their own velocity steps, and why.
  std::vector<ViewBody> worldline_bodies, velocity_bodies;
  std::string worldline_legend, velocity_legend;

  /// A gas: its granular temperature T(t) (t [s], T [J]), from the start to end_time (held
  /// after the last collision), and Haff's law T0 / (1 + t/tau)^2 fitted to it (core::fitHaff;
  /// haff_ok false when it cannot be fitted), with its legend. rviz's T(t) panel draws these.
  std::vector<std::pair<double, double>> temperature;
  bool haff_ok = false;
  double haff_t0 = 0.0;   ///< [J]
  double haff_tau = 0.0;  ///< [s]
  std::string temperature_legend;
  /// How well Haff's law fits and over what window, for the page ("" without a fit).
  std::string temperature_fit_note;

  /// The x-t diagram's end time [s]: the run's end (endTime), every worldline reaches it.
  double end_time = 0.0;
};

/// "1 collision", "31,415 collisions".
std::string collisionsText(std::uint64_t n);
/// "#rrggbb" of rviz's palette colour i (layout::kParticleRgb, repeating).
std::string bodyColourHex(std::size_t i);
/// A number for people: `significant_digits` digits ("%.4g") without e-notation ("0.0065",
/// "2.119×10^8"): rviz's font has code points below 1000 only, so no superscript digits.
std::string numberText(double value, int significant_digits = 4);

RunView makeRunView(const RunRecord& run);

/// One worldline to draw: body `body`'s (t [s], x [m]) polylines, each continuous. They run
/// from 0 to end_time (after its last impact a body flies freely to the run's end); on a
/// ring they lie in [0, L) and are cut at the seam, so no segment spans it.
struct WorldlineSegments {
  std::size_t body = 0;
  std::vector<std::vector<std::pair<double, double>>> segments;
};
/// The x-t diagram's lines for the tracked bodies (RunRecord::trackedBodies).
std::vector<WorldlineSegments> worldlineSegments(const RunRecord& run, double end_time);
/// The view as the run JSON's "view" object (the same fields, the same texts).
nlohmann::json viewJson(const RunView& view);

}  // namespace collision_lab_ros
