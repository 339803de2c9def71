// The wedge in velocity space s-perp (the paper's Figure 1), for three bodies with at most
// one wall: lines L_AB and L_BC, the escape cone, u_perp after the collisions (simulated
// and by the closed form), and the cursor at u_perp now. With e < 1 the path spirals in;
// the directions of u_perp are shown on the circle too, and when the cycle's map has real
// eigenvalues (e <= r_c, a collapse) its eigen-directions, which those directions approach.
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "collision_lab/core/wedge.h"
#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

/// The plane s-perp of mass-weighted velocity space u = S v, seen in the core's wedge
/// basis (r_BC, n_BC) (core/wedge.h), so that the angle of a point is the paper's psi and
/// the ray r_AB lies at +alpha. A wall is the m -> inf limit: its axis is s.
class WedgeFrame {
 public:
  explicit WedgeFrame(const collision_lab::InitialConditions& input)
      : input_(input), wedge_(collision_lab::core::wedgeOf<double>(toArray3(input.masses))) {
    for (int i = 0; i < 3; ++i) {
      if (isWall(input, i)) wall_ = i;
    }
  }

  /// u_perp of velocities v [m/s] as (r_BC, n_BC) coordinates [sqrt(kg) m/s].
  std::array<double, 2> project(const Vec3& v) const {
    double reference = 0.0;
    if (wall_ >= 0) {
      reference = v[wall_];
    } else {
      double p = 0.0, m = 0.0;
      for (int i = 0; i < 3; ++i) p += input_.masses[i] * v[i], m += input_.masses[i];
      reference = p / m;
    }
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) u[i] = i == wall_ ? 0.0 : std::sqrt(input_.masses[i]) * (v[i] - reference);
    return wedge_.coordinates(u);
  }

  /// Angle of r_AB from r_BC: the cone's opening, alpha [rad].
  double abAngle() const { return wedge_.alpha; }
  /// The core's eigen-directions of the AB+BC cycle (core::cycleEigenDirections).
  std::vector<std::array<double, 2>> cycleEigenDirections(double e_ab, double e_bc) const {
    return collision_lab::core::cycleEigenDirections(wedge_, e_ab, e_bc);
  }

 private:
  const collision_lab::InitialConditions& input_;
  collision_lab::core::Wedge<double> wedge_;
  int wall_ = -1;
};

/// Scale from u_perp to rviz units: |u_perp| is conserved, so the path lies on a circle.
double wedgeScale(const WedgeFrame& frame, const RunRecord& run) {
  const auto u0 = frame.project(toArray3(run.input().velocities));
  const double r = std::hypot(u0[0], u0[1]);
  return r > 0 ? kPathRadius / r : 1.0;
}

geometry_msgs::Point wedgePoint(const std::array<double, 2>& u, double scale, double z = 0.0) {
  return point(kWedgeX + scale * u[0], kWedgeY + scale * u[1], z);
}

geometry_msgs::Point onCircle(double radius, double angle, double z = 0.0) {
  return point(kWedgeX + radius * std::cos(angle), kWedgeY + radius * std::sin(angle), z);
}

/// The cone of opening a [rad], the lines L_BC (along e1) and L_AB, and the circle of u_perp.
void addWedgeGeometry(const Canvas& c, double a) {
  Marker cone = c.base(ns::kWedge, kWedgeCone, Marker::TRIANGLE_LIST);
  cone.color = color(kConeFill);
  for (int k = 0; k < kConeSegments; ++k) {
    cone.points.push_back(point(kWedgeX, kWedgeY, kConeZ));
    cone.points.push_back(onCircle(kWedgeRadius, a * k / kConeSegments, kConeZ));
    cone.points.push_back(onCircle(kWedgeRadius, a * (k + 1) / kConeSegments, kConeZ));
  }
  c.add(cone);
  Marker l = c.lines(ns::kWedge, kWedgeLines, Marker::LINE_LIST, kWedgeLineWidth, color(kWhite));
  for (double angle : {0.0, a}) {
    l.points.push_back(onCircle(-kWedgeRadius, angle));
    l.points.push_back(onCircle(kWedgeRadius, angle));
  }
  c.add(l);
  c.add(c.text(ns::kWedge, kWedgeBcLabel, kWedgeX + kLineLabelRadius, kWedgeY, "L_BC", kSmallTextSize));
  geometry_msgs::Point ab = onCircle(kLineLabelRadius, a);
  c.add(c.text(ns::kWedge, kWedgeAbLabel, ab.x, ab.y + (a < kNarrowCone ? kNarrowConeDy : 0.0), "L_AB",
               kSmallTextSize));
  Marker circle = c.lines(ns::kWedge, kWedgeCircle, Marker::LINE_STRIP, kCircleWidth, color(kGrey));
  for (int k = 0; k <= kCircleSegments; ++k) circle.points.push_back(onCircle(kPathRadius, 2 * M_PI * k / kCircleSegments));
  c.add(circle);
}

/// Restitution of pair p [1] (InitialConditions: none, one for all, or one per pair).
double restitutionOf(const collision_lab::InitialConditions& input, std::size_t p) {
  const auto& e = input.restitution;
  return e.empty() ? 1.0 : e.size() == 1 ? e[0] : p < e.size() ? e[p] : 1.0;
}

/// Where u_perp goes after each cycle, for a collapse: the eigen-directions of the cycle
/// map after a BC impact (AB then BC) and after an AB impact (BC then AB), as lines
/// through the centre.
void addEigenDirections(const Canvas& c, const WedgeFrame& wedge) {
  Marker lines = c.lines(ns::kWedge, kWedgeEigen, Marker::LINE_LIST, kWedgeLineWidth, color(kPredicted));
  for (const auto& d : wedge.cycleEigenDirections(restitutionOf(c.run.input(), 0), restitutionOf(c.run.input(), 1))) {
    lines.points.push_back(point(kWedgeX - kWedgeRadius * d[0], kWedgeY - kWedgeRadius * d[1], kDotZ));
    lines.points.push_back(point(kWedgeX + kWedgeRadius * d[0], kWedgeY + kWedgeRadius * d[1], kDotZ));
  }
  c.addLines(lines);
}

/// The directions of u_perp after the shown collisions, on the circle. Near a collapse
/// u_perp shrinks geometrically; below kDirectionFloor of its start its direction is
/// rounding noise of the double velocities, and is not drawn.
void addDirections(const Canvas& c, const WedgeFrame& wedge, const std::vector<const Keyframe*>& shown) {
  constexpr double kDirectionFloor = 1e-9;
  const auto u0 = wedge.project(toArray3(c.run.input().velocities));
  const double floor = kDirectionFloor * std::hypot(u0[0], u0[1]);
  Marker dirs = c.dots(ns::kWedge, kWedgeDirections, kPredictedWedgeDotSize, color(kConeYellow));
  for (const Keyframe* f : shown) {
    const auto u = wedge.project(toArray3(f->velocities));
    const double r = std::hypot(u[0], u[1]);
    if (r > floor && std::isfinite(r)) dirs.points.push_back(onCircle(kPathRadius, std::atan2(u[1], u[0]), kDotZ));
  }
  if (!dirs.points.empty()) c.add(dirs);
}

bool inelastic(const collision_lab::InitialConditions& input) {
  return restitutionOf(input, 0) < 1 || restitutionOf(input, 1) < 1;
}

/// The legend's line on e: the spiral, or (the view names a collapse) the collapse with r_c.
std::string restitutionLegend(const Canvas& c) {
  const RunRecord& run = c.run;
  const double e0 = restitutionOf(run.input(), 0), e1 = restitutionOf(run.input(), 1);
  std::string s = e0 == e1 ? format("e = %.4g", e0) : format("e_AB = %.4g", e0) + format(", e_BC = %.4g", e1);
  const double r_c = run.prediction ? run.prediction->critical_restitution : std::nan("");
  if (std::isfinite(r_c)) s += format(", r_c = %.4g", r_c);
  s += !c.view.collapse.empty() ? ": collapse; violet: eigen-directions" : ": a spiral (shrinks each cycle)";
  return s;
}

/// The orange key in the legend row; under the caption (at most two lines, within the
/// column) what the yellow and violet marks are (violet only when `predicted` dots are
/// drawn) and, for e < 1, the restitution.
void addWedgeLegend(const Canvas& c, const std::vector<const Keyframe*>& shown, bool lossy, bool predicted) {
  const RunRecord& run = c.run;
  // A collapse record is no collision: it is counted on its own.
  const auto collapses = static_cast<std::uint64_t>(
      std::count_if(shown.begin(), shown.end(), [](const Keyframe* f) { return f->collapse; }));
  const std::uint64_t impacts = shown.size() - collapses;
  std::string which = impacts == run.collisions() ? (collapses > 0 ? collisionsText(impacts) : "each collision")
                                                  : withSeparators(impacts) + " of " + collisionsText(run.collisions());
  if (collapses > 0) which += collapses == 1 ? " and a collapse" : " and " + withSeparators(collapses) + " collapses";
  c.add(c.text(ns::kWedge, kWedgeKey, kWedgeX, kLegendY, wrapped("orange: u_perp after " + which, kSmallTextSize, kLeftTextWidth),
               kSmallTextSize, color(kLabelGrey)));
  const std::string rest = lossy       ? "yellow: its direction; " + restitutionLegend(c)
                           : predicted ? "violet: closed form"
                                       : "";
  if (rest.empty()) return;
  c.add(c.text(ns::kWedge, kWedgeLegend, kWedgeX, kWedgeBox.bottom + kWedgeLegendDy,
               wrapped(rest, kSmallTextSize, kLeftTextWidth), kSmallTextSize));
}

}  // namespace

void drawWedge(const Canvas& c) {
  if (sideView(c.run) != SideView::kWedge) return;
  const RunRecord& run = c.run;
  const WedgeFrame wedge(run.input());
  const double scale = wedgeScale(wedge, run);
  addWedgeGeometry(c, wedge.abAngle());
  const auto& frames = run.keyframes();
  // The path joins consecutive states only while every collision is kept.
  const bool every_collision = frames.size() == run.collisions() && run.missedCollisions() == 0;
  Marker path = c.lines(ns::kWedge, kWedgePath, Marker::LINE_STRIP, kPathWidth, color(kPathOrange));
  Marker sim = c.dots(ns::kWedge, kWedgeSimulated, kSimulatedDotSize, color(kSimulatedOrange));
  Marker pred = c.dots(ns::kWedge, kWedgePredicted, kPredictedWedgeDotSize, color(kPredicted));
  const auto start = wedgePoint(wedge.project(toArray3(run.input().velocities)), scale);
  path.points.push_back(start);
  sim.points.push_back(start);
  if (every_collision) {
    for (const Keyframe& f : frames) path.points.push_back(wedgePoint(wedge.project(toArray3(f.velocities)), scale));
  }
  // Spheres are costly in rviz: at most kMaxWedgeDots of them per series.
  const auto shown = thinned(frames, kMaxWedgeDots);
  for (const Keyframe* f : shown) {
    sim.points.push_back(wedgePoint(wedge.project(toArray3(f->velocities)), scale));
    if (f->predicted.size() == 3) pred.points.push_back(wedgePoint(wedge.project(toArray3(f->predicted)), scale, kDotZ));
  }
  const bool lossy = inelastic(run.input());
  if (lossy) {
    addDirections(c, wedge, shown);
    if (!c.view.collapse.empty()) addEigenDirections(c, wedge);
  }
  c.addLines(path);
  c.add(sim);
  if (!pred.points.empty()) c.add(pred);
  c.add(c.text(ns::kWedge, kWedgeStartLabel, start.x, start.y + kStartLabelDy, "start", kSmallTextSize));
  c.add(c.text(ns::kWedge, kWedgeTitle, kWedgeX, kPanelTitleY, "velocity space s-perp (u = S v)", kTextSize));
  c.add(c.text(ns::kWedge, kWedgeCaption, kWedgeX, kWedgeBox.bottom + kCaptionDy,
               "yellow: escape cone, alpha = " + format("%.4g rad", wedge.abAngle()), kSmallTextSize,
               color(kConeYellow)));
  addWedgeLegend(c, shown, lossy, !pred.points.empty());
}

void drawWedgeCursor(const Canvas& c, const SceneState& state) {
  if (sideView(c.run) != SideView::kWedge) return;
  const WedgeFrame wedge(c.run.input());
  Marker now = c.base(ns::kWedgeNow, kCursor, Marker::SPHERE);
  now.pose.position = wedgePoint(wedge.project(toArray3(state.velocities)), wedgeScale(wedge, c.run), kCursorZ);
  now.scale.x = now.scale.y = now.scale.z = kCursorSize;
  c.add(now);
}

}  // namespace collision_lab_ros::markers
