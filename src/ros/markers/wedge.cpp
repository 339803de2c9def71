// The wedge in velocity space s-perp (the paper's Figure 1): lines L_AB and L_BC, the
// escape cone, u_perp after the collisions (simulated and by the closed form), and the
// cursor at u_perp now.
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

}  // namespace

void drawWedge(const Canvas& c) {
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
    for (const Keyframe& f : frames) path.points.push_back(wedgePoint(wedge.project(f.velocities), scale));
  }
  // Spheres are costly in rviz: at most kMaxWedgeDots of them per series.
  const auto shown = thinned(frames, kMaxWedgeDots);
  for (const Keyframe* f : shown) {
    sim.points.push_back(wedgePoint(wedge.project(f->velocities), scale));
    pred.points.push_back(wedgePoint(wedge.project(f->predicted), scale, kDotZ));
  }
  c.addLines(path);
  c.add(sim);
  if (!pred.points.empty()) c.add(pred);
  c.add(c.text(ns::kWedge, kWedgeStartLabel, start.x, start.y + kStartLabelDy, "start", kSmallTextSize));
  c.add(c.text(ns::kWedge, kWedgeTitle, kWedgeX, kPanelTitleY, "velocity space s-perp (u = S v)", kTextSize));
  c.add(c.text(ns::kWedge, kWedgeCaption, kWedgeX, kWedgeBox.bottom + kCaptionDy,
               "yellow: escape cone, alpha = " + format("%.4g rad", wedge.abAngle()), kSmallTextSize,
               color(kConeYellow)));
  const std::string which = shown.size() == run.collisions()
                                ? "each collision"
                                : withSeparators(shown.size()) + " of " + withSeparators(run.collisions()) + " collisions";
  c.add(c.text(ns::kWedge, kWedgeLegend, kWedgeX, kWedgeBox.bottom + kWedgeLegendDy,
               "orange: u_perp after " + which + "\nviolet: closed form", kSmallTextSize));
}

void drawWedgeCursor(const Canvas& c, const SceneState& state) {
  const WedgeFrame wedge(c.run.input());
  Marker now = c.base(ns::kWedgeNow, kCursor, Marker::SPHERE);
  now.pose.position = wedgePoint(wedge.project(state.velocities), wedgeScale(wedge, c.run), kCursorZ);
  now.scale.x = now.scale.y = now.scale.z = kCursorSize;
  c.add(now);
}

}  // namespace collision_lab_ros::markers
