#include "collision_lab/ros/marker_builder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <geometry_msgs/Point.h>
#include <std_msgs/ColorRGBA.h>

namespace collision_lab_ros {

namespace {

using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;
using Vec3 = std::array<double, 3>;

// Layout of the three views in the marker frame [rviz units].
constexpr double kSceneY = 5.2, kSceneLeft = -9.5, kSceneRight = 14.5;
constexpr double kWedgeX = -6.4, kWedgeY = -2.0, kWedgeRadius = 3.2;
constexpr double kPlotLeft = 0.0, kPlotRight = 9.4, kPlotBottom = -5.2, kPlotTop = 1.2;
constexpr double kBarsLeft = 11.6, kBarsPitch = 1.1, kBarsBottom = -5.2, kBarsHeight = 6.4;
constexpr double kTitleY = 2.6;
constexpr double kTextSize = 0.38, kSmallTextSize = 0.3, kTitleSize = 0.46;
constexpr const char* kNames[3] = {"A", "B", "C"};

std_msgs::ColorRGBA color(double r, double g, double b, double a = 1.0) {
  std_msgs::ColorRGBA c;
  c.r = r; c.g = g; c.b = b; c.a = a;
  return c;
}
std_msgs::ColorRGBA particleColor(int i, double lighten = 0.0) {
  static const double rgb[3][3] = {{0.9, 0.2, 0.2}, {0.2, 0.75, 0.25}, {0.25, 0.45, 1.0}};
  return color(rgb[i][0] + (1 - rgb[i][0]) * lighten, rgb[i][1] + (1 - rgb[i][1]) * lighten,
               rgb[i][2] + (1 - rgb[i][2]) * lighten);
}
const std_msgs::ColorRGBA kWhite = color(0.95, 0.95, 0.95);
const std_msgs::ColorRGBA kGrey = color(0.6, 0.6, 0.6);

geometry_msgs::Point point(double x, double y, double z = 0.0) {
  geometry_msgs::Point p;
  p.x = x; p.y = y; p.z = z;
  return p;
}

Marker base(const std::string& frame_id, const std::string& ns, int id, int type) {
  Marker m;
  m.header.frame_id = frame_id;  // stamp 0: rviz uses the latest transform
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.color = kWhite;
  return m;
}

Marker text(const std::string& frame_id, const std::string& ns, int id, double x, double y,
            const std::string& s, double size = kTextSize,
            const std_msgs::ColorRGBA& c = kWhite) {
  Marker m = base(frame_id, ns, id, Marker::TEXT_VIEW_FACING);
  m.pose.position = point(x, y, 0.2);
  m.scale.z = size;
  m.color = c;
  m.text = s;
  return m;
}

Marker lines(const std::string& frame_id, const std::string& ns, int id, int type,
             double width, const std_msgs::ColorRGBA& c) {
  Marker m = base(frame_id, ns, id, type);
  m.scale.x = width;
  m.color = c;
  return m;
}

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
}

bool isWall(const collision_lab::InitialConditions& input, int i) {
  return std::isinf(input.masses[i]);
}

// ---- velocity space ----

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 scaled(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
Vec3 normalized(const Vec3& a) {
  const double n = std::sqrt(dot(a, a));
  return n > 0 ? scaled(a, 1.0 / n) : a;
}

/// The plane s-perp of mass-weighted velocity space u = S v, seen in the basis
/// (e1, e2) with e1 along the escape cone's ray r_BC and r_AB on the side of +e2, so that
/// the angle of a point is the paper's psi. A wall is the m -> inf limit: its axis is s.
class WedgeFrame {
 public:
  explicit WedgeFrame(const collision_lab::InitialConditions& input) : input_(input) {
    Vec3 inv_sqrt{}, s{};
    for (int i = 0; i < 3; ++i) {
      inv_sqrt[i] = isWall(input, i) ? 0.0 : 1.0 / std::sqrt(input.masses[i]);
      s[i] = isWall(input, i) ? 0.0 : std::sqrt(input.masses[i]);
      if (isWall(input, i)) wall_ = i;
    }
    if (wall_ >= 0) s = Vec3{}, s[wall_] = 1.0;
    s_hat_ = normalized(s);
    const Vec3 n_ab{inv_sqrt[0], -inv_sqrt[1], 0.0};
    const Vec3 n_bc{0.0, inv_sqrt[1], -inv_sqrt[2]};
    Vec3 r_bc = normalized(cross(s_hat_, n_bc));
    if (dot(n_ab, r_bc) < 0) r_bc = scaled(r_bc, -1.0);
    Vec3 r_ab = normalized(cross(s_hat_, n_ab));
    if (dot(n_bc, r_ab) < 0) r_ab = scaled(r_ab, -1.0);
    e1_ = r_bc;
    e2_ = cross(s_hat_, e1_);
    if (dot(r_ab, e2_) < 0) e2_ = scaled(e2_, -1.0);
    ab_angle_ = std::atan2(dot(r_ab, e2_), dot(r_ab, e1_));
  }

  /// u_perp of velocities v [m/s] as (e1, e2) coordinates [sqrt(kg) m/s].
  std::array<double, 2> project(const Vec3& v) const {
    double reference = 0.0;
    if (wall_ >= 0) {
      reference = v[wall_];
    } else {
      double p = 0.0, m = 0.0;
      for (int i = 0; i < 3; ++i) p += input_.masses[i] * v[i], m += input_.masses[i];
      reference = p / m;
    }
    Vec3 u{};
    for (int i = 0; i < 3; ++i) {
      u[i] = i == wall_ ? 0.0 : std::sqrt(input_.masses[i]) * (v[i] - reference);
    }
    return {dot(u, e1_), dot(u, e2_)};
  }

  /// Angle of r_AB from r_BC: the cone's opening, alpha [rad].
  double abAngle() const { return ab_angle_; }

 private:
  const collision_lab::InitialConditions& input_;
  int wall_ = -1;
  Vec3 s_hat_{}, e1_{}, e2_{};
  double ab_angle_ = 0.0;
};

Vec3 toVec(const boost::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

/// Scale from u_perp to rviz units: |u_perp| is conserved, so the path lies on a circle.
double wedgeScale(const WedgeFrame& frame, const RunRecord& run) {
  const auto u0 = frame.project(toVec(run.input.velocities));
  const double r = std::hypot(u0[0], u0[1]);
  return r > 0 ? 0.8 * kWedgeRadius / r : 1.0;
}

geometry_msgs::Point wedgePoint(const std::array<double, 2>& u, double scale, double z = 0.0) {
  return point(kWedgeX + scale * u[0], kWedgeY + scale * u[1], z);
}

// ---- scene ----

struct SceneAxis {
  double min = 0.0, max = 1.0;
  double toX(double position) const {
    return kSceneLeft + (position - min) / (max - min) * (kSceneRight - kSceneLeft);
  }
};

SceneAxis sceneAxis(const RunRecord& run) {
  SceneAxis axis{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  const auto include = [&axis](const std::array<double, 3>& x) {
    for (double v : x) {
      if (std::isfinite(v)) axis.min = std::min(axis.min, v), axis.max = std::max(axis.max, v);
    }
  };
  include(stateAt(run, 0.0).positions);
  for (const auto& e : run.events) include(toVec(e.positions));
  include(stateAt(run, loopDuration(run)).positions);
  if (!(axis.max > axis.min)) {
    const double centre = std::isfinite(axis.min) ? axis.min : 0.0;
    axis.min = centre - 1.0, axis.max = centre + 1.0;
  }
  const double pad = 0.05 * (axis.max - axis.min);
  axis.min -= pad, axis.max += pad;
  return axis;
}

double bodyDiameter(const collision_lab::InitialConditions& input, int i) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (int j = 0; j < 3; ++j) {
    if (!isWall(input, j)) lo = std::min(lo, input.masses[j]), hi = std::max(hi, input.masses[j]);
  }
  const double decades = std::max(std::log10(hi / lo), 1.0);
  return 0.35 + 0.55 * std::log10(input.masses[i] / lo) / decades;
}

// ---- plots ----

struct PlotAxes {
  double v_min = -1.0, v_max = 1.0;
  std::size_t n = 0;
  double toX(double index) const {
    return kPlotLeft + (n ? index / static_cast<double>(n) : 0.0) * (kPlotRight - kPlotLeft);
  }
  double toY(double v) const {
    return kPlotBottom + (v - v_min) / (v_max - v_min) * (kPlotTop - kPlotBottom);
  }
};

PlotAxes plotAxes(const RunRecord& run) {
  PlotAxes axes{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                run.velocities.size()};
  const auto include = [&axes](double v) {
    if (std::isfinite(v)) axes.v_min = std::min(axes.v_min, v), axes.v_max = std::max(axes.v_max, v);
  };
  for (double v : run.input.velocities) include(v);
  for (const auto& v : run.velocities) {
    for (double x : {v.v_a, v.v_b, v.v_c, v.predicted_v_a, v.predicted_v_b, v.predicted_v_c}) include(x);
  }
  if (!(axes.v_max > axes.v_min)) {
    const double centre = std::isfinite(axes.v_min) ? axes.v_min : 0.0;
    axes.v_min = centre - 1.0, axes.v_max = centre + 1.0;
  }
  const double pad = 0.06 * (axes.v_max - axes.v_min);
  axes.v_min -= pad, axes.v_max += pad;
  return axes;
}

std::array<double, 3> simulated(const collision_lab::Velocities& v) { return {v.v_a, v.v_b, v.v_c}; }
std::array<double, 3> predicted(const collision_lab::Velocities& v) {
  return {v.predicted_v_a, v.predicted_v_b, v.predicted_v_c};
}

std::string runTitle(const RunRecord& run) {
  std::string title = "run " + run.input.run_id;
  if (run.prediction) {
    title += ":  predicted " + std::to_string(run.prediction->collision_count) + " collisions";
    title += run.prediction->paper_count_defined
                 ? ",  paper's eq. (3.22): " + std::to_string(run.prediction->paper_collision_count)
                 : ",  paper's eq. (3.22): undefined";
  }
  if (run.summary) {
    title += ",  simulated " + std::to_string(run.summary->collision_count) +
             (run.summary->truncated ? " (truncated)" : "");
  }
  return title;
}

}  // namespace

SceneState stateAt(const RunRecord& run, double t) {
  const auto later = std::upper_bound(
      run.events.begin(), run.events.end(), t,
      [](double time, const collision_lab::CollisionEvent& e) { return time < e.time; });
  SceneState state;
  state.collisions = static_cast<std::size_t>(later - run.events.begin());
  double since = t;
  if (state.collisions == 0) {
    state.positions = toVec(run.input.positions);
    state.velocities = toVec(run.input.velocities);
  } else {
    const auto& last = *(later - 1);
    state.positions = toVec(last.positions);
    state.velocities = toVec(last.velocities_after);
    since = t - last.time;
  }
  for (int i = 0; i < 3; ++i) state.positions[i] += state.velocities[i] * since;
  return state;
}

double loopDuration(const RunRecord& run) {
  if (!run.events.empty() && run.events.back().time > 0) return 1.25 * run.events.back().time;
  // No collision (or all at t = 0): long enough for the fastest body to cross the gaps.
  double gap = 0.0, speed = 0.0;
  for (int i = 0; i < 2; ++i) gap = std::max(gap, run.input.positions[i] - run.input.positions[i + 1]);
  for (double v : run.input.velocities) speed = std::max(speed, std::abs(v));
  return speed > 0 && gap > 0 ? gap / speed : 1.0;
}

MarkerArray buildStaticMarkers(const RunRecord& run, const std::string& frame_id) {
  MarkerArray array;
  auto& out = array.markers;
  out.push_back(text(frame_id, "title", 0, 2.5, kSceneY + 2.3, runTitle(run), kTitleSize));

  // Scene: the line the bodies move on.
  {
    Marker axis = lines(frame_id, "scene", 0, Marker::LINE_LIST, 0.03, kGrey);
    axis.points = {point(kSceneLeft, kSceneY), point(kSceneRight, kSceneY)};
    out.push_back(axis);
    const SceneAxis scene_axis = sceneAxis(run);
    out.push_back(text(frame_id, "scene", 1, kSceneLeft, kSceneY - 0.5,
                       format("%.3g m", scene_axis.min), kSmallTextSize, kGrey));
    out.push_back(text(frame_id, "scene", 2, kSceneRight, kSceneY - 0.5,
                       format("%.3g m", scene_axis.max), kSmallTextSize, kGrey));
    out.push_back(text(frame_id, "scene", 3, (kSceneLeft + kSceneRight) / 2, kSceneY - 1.2,
                       "x [m] (to scale; bodies sized by log mass)", kSmallTextSize, kGrey));
  }

  // Wedge.
  const WedgeFrame wedge(run.input);
  const double scale = wedgeScale(wedge, run);
  {
    const double a = wedge.abAngle();
    Marker cone = base(frame_id, "wedge", 0, Marker::TRIANGLE_LIST);
    cone.color = color(1.0, 0.85, 0.2, 0.35);
    constexpr int kSegments = 32;
    for (int k = 0; k < kSegments; ++k) {
      const double a0 = a * k / kSegments, a1 = a * (k + 1) / kSegments;
      cone.points.push_back(point(kWedgeX, kWedgeY, -0.01));
      cone.points.push_back(point(kWedgeX + kWedgeRadius * std::cos(a0),
                                  kWedgeY + kWedgeRadius * std::sin(a0), -0.01));
      cone.points.push_back(point(kWedgeX + kWedgeRadius * std::cos(a1),
                                  kWedgeY + kWedgeRadius * std::sin(a1), -0.01));
    }
    out.push_back(cone);

    Marker l = lines(frame_id, "wedge", 1, Marker::LINE_LIST, 0.035, kWhite);
    for (double angle : {0.0, a}) {
      l.points.push_back(point(kWedgeX - kWedgeRadius * std::cos(angle),
                               kWedgeY - kWedgeRadius * std::sin(angle)));
      l.points.push_back(point(kWedgeX + kWedgeRadius * std::cos(angle),
                               kWedgeY + kWedgeRadius * std::sin(angle)));
    }
    out.push_back(l);
    out.push_back(text(frame_id, "wedge", 2, kWedgeX + 1.12 * kWedgeRadius, kWedgeY, "L_BC"));
    out.push_back(text(frame_id, "wedge", 3, kWedgeX + 1.12 * kWedgeRadius * std::cos(a),
                       kWedgeY + 1.12 * kWedgeRadius * std::sin(a) + (a < 0.3 ? 0.45 : 0.0),
                       "L_AB"));

    Marker circle = lines(frame_id, "wedge", 5, Marker::LINE_STRIP, 0.015, kGrey);
    for (int k = 0; k <= 96; ++k) {
      const double angle = 2 * M_PI * k / 96;
      circle.points.push_back(point(kWedgeX + 0.8 * kWedgeRadius * std::cos(angle),
                                    kWedgeY + 0.8 * kWedgeRadius * std::sin(angle)));
    }
    out.push_back(circle);

    Marker path = lines(frame_id, "wedge", 6, Marker::LINE_STRIP, 0.03, color(1.0, 0.55, 0.1, 0.8));
    Marker sim = base(frame_id, "wedge", 7, Marker::SPHERE_LIST);
    sim.scale.x = sim.scale.y = sim.scale.z = 0.2;
    sim.color = color(1.0, 0.55, 0.1);
    Marker pred = base(frame_id, "wedge", 8, Marker::SPHERE_LIST);
    pred.scale.x = pred.scale.y = pred.scale.z = 0.1;
    pred.color = color(0.75, 0.35, 1.0);
    const auto start = wedge.project(toVec(run.input.velocities));
    path.points.push_back(wedgePoint(start, scale));
    sim.points.push_back(wedgePoint(start, scale));
    for (const auto& e : run.events) {
      path.points.push_back(wedgePoint(wedge.project(toVec(e.velocities_after)), scale));
      sim.points.push_back(path.points.back());
      pred.points.push_back(wedgePoint(wedge.project(toVec(e.predicted_velocities_after)), scale, 0.05));
    }
    if (path.points.size() >= 2) out.push_back(path);
    out.push_back(sim);
    if (!pred.points.empty()) out.push_back(pred);
    const auto s = wedgePoint(start, scale);
    out.push_back(text(frame_id, "wedge", 9, s.x, s.y - 0.35, "start", kSmallTextSize));
    out.push_back(text(frame_id, "wedge", 10, kWedgeX, kTitleY,
                       "velocity space s-perp (u = S v): u_perp per collision", kTextSize));
    out.push_back(text(frame_id, "wedge", 4, kWedgeX, kWedgeY - kWedgeRadius - 0.3,
                       "yellow: escape cone, alpha = " + format("%.4g rad", a), kSmallTextSize,
                       color(1.0, 0.85, 0.2)));
    out.push_back(text(frame_id, "wedge", 11, kWedgeX, kWedgeY - kWedgeRadius - 0.75,
                       "orange: simulated   violet: predicted   white: now", kSmallTextSize));
  }

  // Velocity plot.
  const PlotAxes axes = plotAxes(run);
  {
    Marker frame = lines(frame_id, "plot", 0, Marker::LINE_LIST, 0.03, kGrey);
    frame.points = {point(kPlotLeft, kPlotBottom), point(kPlotRight, kPlotBottom),
                    point(kPlotLeft, kPlotBottom), point(kPlotLeft, kPlotTop)};
    if (axes.v_min < 0 && axes.v_max > 0) {
      frame.points.push_back(point(kPlotLeft, axes.toY(0.0)));
      frame.points.push_back(point(kPlotRight, axes.toY(0.0)));
    }
    out.push_back(frame);
    out.push_back(text(frame_id, "plot", 1, (kPlotLeft + kPlotRight) / 2, kPlotBottom - 0.45,
                       "collision index", kSmallTextSize));
    out.push_back(text(frame_id, "plot", 2, kPlotLeft, kPlotBottom - 0.45, "0", kSmallTextSize));
    out.push_back(text(frame_id, "plot", 3, kPlotRight, kPlotBottom - 0.45,
                       std::to_string(axes.n), kSmallTextSize));
    out.push_back(text(frame_id, "plot", 4, kPlotLeft - 0.75, axes.toY(axes.v_max),
                       format("%.3g", axes.v_max), kSmallTextSize));
    out.push_back(text(frame_id, "plot", 5, kPlotLeft - 0.75, axes.toY(axes.v_min),
                       format("%.3g", axes.v_min), kSmallTextSize));
    if (axes.v_min < 0 && axes.v_max > 0) {
      out.push_back(text(frame_id, "plot", 6, kPlotLeft - 0.75, axes.toY(0.0), "0", kSmallTextSize));
    }
    out.push_back(text(frame_id, "plot", 7, (kPlotLeft + kPlotRight) / 2, kTitleY,
                       "v [m/s] vs collision index: lines simulated, dots predicted", kTextSize));
    for (int i = 0; i < 3; ++i) {
      Marker line = lines(frame_id, "plot", 10 + i, Marker::LINE_STRIP, 0.04, particleColor(i));
      line.points.push_back(point(axes.toX(0), axes.toY(run.input.velocities[i])));
      Marker dots = base(frame_id, "plot", 20 + i, Marker::SPHERE_LIST);
      dots.scale.x = dots.scale.y = dots.scale.z = 0.13;
      dots.color = particleColor(i, 0.55);
      for (std::size_t k = 0; k < run.velocities.size(); ++k) {
        line.points.push_back(point(axes.toX(k + 1.0), axes.toY(simulated(run.velocities[k])[i])));
        dots.points.push_back(point(axes.toX(k + 1.0), axes.toY(predicted(run.velocities[k])[i]), 0.05));
      }
      if (line.points.size() == 1) line.points.push_back(point(kPlotRight, line.points[0].y));
      out.push_back(line);
      if (!dots.points.empty()) out.push_back(dots);
      out.push_back(text(frame_id, "plot", 30 + i, kPlotRight + 0.5, kPlotTop - 0.45 * i,
                         std::string("v_") + kNames[i], kTextSize, particleColor(i)));
    }
  }

  // Energy bars: axis and names (the bars move).
  {
    Marker axis = lines(frame_id, "energy", 0, Marker::LINE_LIST, 0.03, kGrey);
    axis.points = {point(kBarsLeft - 0.6, kBarsBottom), point(kBarsLeft + 2 * kBarsPitch + 0.6, kBarsBottom)};
    out.push_back(axis);
    for (int i = 0; i < 3; ++i) {
      out.push_back(text(frame_id, "energy", 1 + i, kBarsLeft + i * kBarsPitch, kBarsBottom - 0.45,
                         isWall(run.input, i) ? std::string(kNames[i]) + " (wall)" : kNames[i],
                         kSmallTextSize, particleColor(i)));
    }
    out.push_back(text(frame_id, "energy", 4, kBarsLeft + kBarsPitch, kTitleY,
                       "kinetic energy [J]", kTextSize));
  }
  return array;
}

MarkerArray buildAnimatedMarkers(const RunRecord& run, double t, const std::string& frame_id) {
  MarkerArray array;
  auto& out = array.markers;
  const SceneState state = stateAt(run, t);

  // Scene: bodies and walls at time t, velocity labels.
  const SceneAxis axis = sceneAxis(run);
  for (int i = 0; i < 3; ++i) {
    const double x = axis.toX(state.positions[i]);
    if (isWall(run.input, i)) {
      Marker wall = base(frame_id, "bodies", i, Marker::CUBE);
      wall.pose.position = point(x + (i == 0 ? 0.1 : -0.1), kSceneY);
      wall.scale.x = 0.2, wall.scale.y = 2.2, wall.scale.z = 0.3;
      wall.color = kGrey;
      out.push_back(wall);
    } else {
      Marker body = base(frame_id, "bodies", i, Marker::SPHERE);
      body.pose.position = point(x, kSceneY);
      body.scale.x = body.scale.y = body.scale.z = bodyDiameter(run.input, i);
      body.color = particleColor(i);
      out.push_back(body);
    }
    // A short tag beside the body (walls: on their outer side), the value in a fixed row.
    const double tag_x = isWall(run.input, i) ? x + (i == 0 ? 0.9 : -0.9) : x;
    const double tag_y = isWall(run.input, i) ? kSceneY + 0.6 : kSceneY + (i == 1 ? -0.75 : 0.75);
    out.push_back(text(frame_id, "labels", i, tag_x, tag_y,
                       isWall(run.input, i) ? std::string(kNames[i]) + "\n(wall)" : kNames[i],
                       kTextSize, particleColor(i, 0.3)));
    out.push_back(text(frame_id, "labels", 10 + i, -3.0 + 5.2 * i, kSceneY + 1.5,
                       std::string("v_") + kNames[i] + format(" = %.4g m/s", state.velocities[i]),
                       kTextSize, particleColor(i, 0.3)));
  }
  out.push_back(text(frame_id, "labels", 3, kSceneLeft + 1.8, kSceneY + 1.5,
                     format("t = %.4g s", t) + ",  collisions " + std::to_string(state.collisions),
                     kTextSize));

  // Wedge: where u_perp is now.
  const WedgeFrame wedge(run.input);
  Marker now = base(frame_id, "wedge_now", 0, Marker::SPHERE);
  now.pose.position = wedgePoint(wedge.project(state.velocities), wedgeScale(wedge, run), 0.1);
  now.scale.x = now.scale.y = now.scale.z = 0.34;
  now.color = kWhite;
  out.push_back(now);

  // Plot cursor at the current collision index.
  const PlotAxes axes = plotAxes(run);
  Marker cursor = lines(frame_id, "plot_cursor", 0, Marker::LINE_LIST, 0.025, color(1, 1, 1, 0.5));
  const double cx = axes.toX(static_cast<double>(std::min(state.collisions, axes.n)));
  cursor.points = {point(cx, kPlotBottom), point(cx, kPlotTop)};
  out.push_back(cursor);

  // Energy bars: kinetic energy after the collisions so far [J].
  std::array<double, 3> kinetic{};
  if (state.collisions > 0 && state.collisions <= run.energies.size()) {
    const auto& e = run.energies[state.collisions - 1];
    kinetic = {e.kinetic_a, e.kinetic_b, e.kinetic_c};
  } else {
    for (int i = 0; i < 3; ++i) {
      if (!isWall(run.input, i)) {
        kinetic[i] = 0.5 * run.input.masses[i] * run.input.velocities[i] * run.input.velocities[i];
      }
    }
  }
  const double total = kinetic[0] + kinetic[1] + kinetic[2];
  for (int i = 0; i < 3; ++i) {
    const double h = std::max(total > 0 ? kBarsHeight * kinetic[i] / total : 0.0, 0.01);
    Marker bar = base(frame_id, "energy_bars", i, Marker::CUBE);
    bar.pose.position = point(kBarsLeft + i * kBarsPitch, kBarsBottom + h / 2);
    bar.scale.x = 0.7, bar.scale.y = h, bar.scale.z = 0.1;
    bar.color = particleColor(i);
    out.push_back(bar);
    out.push_back(text(frame_id, "energy_bars", 10 + i, kBarsLeft + i * kBarsPitch,
                       kBarsBottom + h + 0.3, format("%.3g", kinetic[i]), kSmallTextSize));
  }
  return array;
}

MarkerArray deleteAllMarkers(const std::string& frame_id) {
  MarkerArray array;
  Marker m;
  m.header.frame_id = frame_id;
  m.action = Marker::DELETEALL;
  array.markers.push_back(m);
  return array;
}

}  // namespace collision_lab_ros
