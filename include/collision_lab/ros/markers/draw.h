// What the views share (internal to the marker builders): marker primitives, plot axes
// and frames, the facts of a run that several views show, and one function per view.
// The views draw into a Canvas; the order of their calls is the order of the markers.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <geometry_msgs/Point.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/Marker.h>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/ids.h"
#include "collision_lab/ros/markers/layout.h"
#include "collision_lab/ros/run_view.h"
#include "collision_lab/ros/view_style.h"

namespace collision_lab_ros::markers {

using visualization_msgs::Marker;
using Vec3 = std::array<double, 3>;
using Polyline = std::vector<Envelope::Vertex>;


// ---- primitives ----
std_msgs::ColorRGBA color(const Rgba& c);
/// Body i's colour as the view decided it (RunView::body_colours: the same bytes the page
/// draws), lightened towards white by `lighten` (0..1) for texts.
std_msgs::ColorRGBA bodyColor(const RunView& view, std::size_t i, double lighten = 0.0);
/// velocityRgb as a marker colour.
std_msgs::ColorRGBA velocityColor(double v, double v_max);
/// "A", "B", ... (core::bodyName).
std::string bodyName(std::size_t i);
geometry_msgs::Point point(double x, double y, double z = 0.0);
/// value with its sign always written: "+1.12", "-1.12", "0". rviz's font has no proper
/// minus (U+2212 and the dashes are not drawn) and draws '-' a few pixels wide; beside the
/// '+' of the positive values it still reads as a sign.
std::string withSign(const char* fmt, double value);
/// A position [m] on an axis, one style for every view: four significant digits, no exponent
/// from 1,000 on ("1,060", "-61.06", "0.6058"); a '+' before a positive value when signed_
/// (beside negative ones).
std::string positionText(double x, bool signed_);
/// The longest line of s and the number of its lines [characters, lines].
std::pair<std::size_t, std::size_t> textExtent(const std::string& s);
/// Estimated size of s on screen at text height `size` [rviz units] (rviz's font, see
/// layout::kHalfCharWidth and kHalfLineHeight): the longest line's width, all lines' height.
double textWidth(const std::string& s, double size);
double textHeight(const std::string& s, double size);
/// s with each line broken at spaces so that it fits `width` [rviz units] at `size` (a
/// word wider than that stays whole).
std::string wrapped(const std::string& s, double size, double width);
/// Bodies A, B, C (0, 1, 2) of a per-body array; NaN for a body it does not have.
std::array<double, 3> toArray3(const std::vector<double>& a);
bool isWall(const collision_lab::InitialConditions& input, std::size_t i);
/// Which view takes the wedge's place (markers/ids.h: ns kWedge or kVelocities).
enum class SideView { kWedge, kVelocityProfile, kHistogram };
SideView sideView(const RunRecord& run);
/// More bodies than each can be labelled: sums in the plots (and, as RunView decides it,
/// colours by the start velocity).
bool largeScene(const RunRecord& run);

/// Where a view draws: the run, its view description (the texts, the bodies shown and the
/// T(t) the page shows too: the views draw these, never their own), the frame of its
/// markers, and the array it appends to.
struct Canvas {
  const RunRecord& run;
  const RunView& view;
  const std::string& frame_id;
  std::vector<Marker>& out;

  Marker base(const std::string& ns, int id, int type) const;
  Marker text(const std::string& ns, int id, double x, double y, const std::string& s,
              double size = layout::kTextSize, const std_msgs::ColorRGBA& c = color(layout::kWhite)) const;
  Marker lines(const std::string& ns, int id, int type, double width, const std_msgs::ColorRGBA& c) const;
  Marker dots(const std::string& ns, int id, double size, const std_msgs::ColorRGBA& c) const;
  void add(Marker m) const { out.push_back(std::move(m)); }
  /// Line markers go out only with enough points for rviz (>= 2; LINE_LIST in pairs).
  void addLines(Marker m) const;
};
/// A text and a line marker without a run (the overlays draw over any run).
Marker textMarker(const std::string& frame_id, const std::string& ns, int id, double x, double y,
                  const std::string& s, double size, const std_msgs::ColorRGBA& c);
Marker lineMarker(const std::string& frame_id, const std::string& ns, int id, int type, double width,
                  const std_msgs::ColorRGBA& c);

// ---- plots ----
/// A linear map from data (x in [x0, x1], y in [y0, y1]) into a box; values outside are
/// drawn at its edges.
struct Axes {
  Box box;
  double x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0;
  double toX(double x) const;
  double toY(double y) const;
  bool contains(double y) const { return y >= y0 && y <= y1; }
};
/// [lo, hi] widened to include `always` and padded; [-1, 1] around it when empty.
std::pair<double, double> paddedRange(double lo, double hi, double always = 0.0);
/// The frame, a zero line when 0 is inside, values at the bottom, top and zero, and a
/// bold label over the panel (ids base + kFrame*).
void addFrame(const Canvas& c, const std::string& ns, int base, const Axes& axes, const std::string& label);
/// A series' steps as a LINE_STRIP, plus a dot at its start (id + kSeriesStartDot) when
/// the known part is too short to see on the axis.
void addSeries(const Canvas& c, const std::string& ns, int id, const Polyline& poly, const Axes& axes,
               const std_msgs::ColorRGBA& colour, double width = layout::kSeriesWidth);
/// The segments of a series whose mark exceeds `tolerance`, as a LINE_LIST.
Marker markedSegments(const Canvas& c, const std::string& ns, int id, const Polyline& poly, const Axes& axes,
                      double tolerance, const std_msgs::ColorRGBA& colour);
/// The series' polyline held at its last value up to x_end.
Polyline withTail(const Envelope& e, double x_end);
/// Evenly thinned keyframes, at most `n`.
std::vector<const Keyframe*> thinned(const std::vector<Keyframe>& frames, std::size_t n);
/// Labels of the collision index axis under a box (ids base + label number).
void addIndexAxisLabels(const Canvas& c, const std::string& ns, int base, const Axes& axes);

// ---- facts of the run ----
/// A periodic motion, drawn over one period (x-t diagram and index plots): a ball between two
/// walls at rest, all impacts elastic, once the run lasts layout::kPeriodsToFold periods.
struct Period {
  double time;            ///< T = 2 (x_A - x_C) / |v_B| [s] (core::wallToWallPeriod)
  std::uint64_t impacts;  ///< per period, one on each wall [1]
  /// Whole periods before time t [s].
  std::uint64_t before(double t) const { return static_cast<std::uint64_t>(t / time); }
  /// Collisions since the current period began, given `collisions` so far [1].
  std::uint64_t inPeriod(double t, std::uint64_t collisions) const;
};
std::optional<Period> periodOf(const RunRecord& run);
/// "periods so far: N" at time t [s].
std::string periodsSoFar(const Period& period, double t);
/// The collision index axis runs to this [1]: one past the last drawn step, or past the
/// predicted count when the collisions are not shown one by one; one past a period's
/// impacts for a periodic motion.
double indexAxisEnd(const RunRecord& run, const RunView& view);
/// Velocities after all the collisions when the steps do not get there: the summary's
/// (simulated or, when not simulated, predicted) or the prediction's, at index n.
std::optional<std::pair<std::uint64_t, std::vector<double>>> finalVelocitiesNotDrawn(const RunRecord& run);
std::string runTitle(const RunRecord& run);
/// What the picture does not show, in one line (empty when it shows the whole run).
std::string runNote(const RunRecord& run);
/// The status line: the time and the collisions behind now, the run's counter, collapse,
/// ring and box (RunView's texts), the clock.
std::string statusLine(const RunView& view, const SceneState& state, const FrameClock& clock);

/// The scene's position axis [m] on screen.
struct SceneAxis {
  double min = 0.0, max = 1.0;
  double toX(double position) const;
};
/// Every position the animation can show: the worldlines and the end state.
SceneAxis sceneAxis(const RunRecord& run);
/// Where the scene draws the bodies of `state`: sceneAxis, or for a large scene the bodies'
/// spread now.
SceneAxis bodiesAxis(const RunRecord& run, const SceneState& state);

/// Clusters (markers/clusters.cpp): runs [first, last] (last > first) of neighbouring finite
/// bodies at exactly one position with exactly one velocity, in body order. The messages
/// put a cluster's bodies (stuck by e = 0, or one after a collapse) at one point with one
/// velocity.
std::vector<std::pair<std::size_t, std::size_t>> clustersOf(const RunRecord& run, const std::vector<double>& x,
                                                            const std::vector<double>& v);
/// False when the run cannot have a cluster (no collapse so far and no pair with e = 0).
bool mayCluster(const RunRecord& run);

// ---- the views (static: when a message arrives; animated: every frame) ----
void drawTitle(const Canvas& c);
void drawSceneAxis(const Canvas& c);
void drawWedge(const Canvas& c);
void drawVelocitySteps(const Canvas& c);
void drawConservedSteps(const Canvas& c);
void drawWorldlines(const Canvas& c);
void drawEnergyBarsAxis(const Canvas& c);
void drawSideViewAxes(const Canvas& c);  ///< the velocity profile or the histogram, when not the wedge
void drawTemperature(const Canvas& c);   ///< T(t) and Haff's law of a gas (RunView::gas)

void drawBodies(const Canvas& c, const SceneState& state);
void drawMagnifier(const Canvas& c, const SceneState& state);
void drawStatus(const Canvas& c, const SceneState& state, const FrameClock& clock);
void drawWedgeCursor(const Canvas& c, const SceneState& state);
void drawStepsCursor(const Canvas& c, const SceneState& state);
void drawWorldlinesCursor(const Canvas& c, const SceneState& state);
void drawEnergyBars(const Canvas& c, const SceneState& state);
void drawSideViewNow(const Canvas& c, const SceneState& state);
void drawTemperatureNow(const Canvas& c, const SceneState& state);
void drawClusters(const Canvas& c, const SceneState& state);  ///< rings and names in the scene

}  // namespace collision_lab_ros::markers
