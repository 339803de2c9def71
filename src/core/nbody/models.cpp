#include "collision_lab/core/nbody/models.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "../correct_rounding.h"
#include "../rotation_run.h"
#include "collision_lab/core/wedge.h"
#include "spiral.h"

namespace collision_lab {
namespace core {

namespace {

bool anyApproaching(const Scene& scene) {
  for (std::size_t p = 0; p < scene.contactCount(); ++p) {
    if (scene.velocities[p] < scene.velocities[scene.leftOf(p)]) return true;
  }
  return false;
}

/// A restitution model that can change some impact's e (TC and the threshold only make
/// impacts elastic, so they change nothing in an elastic scene).
bool restitutionModelActs(const Scene& scene) {
  const RestitutionModelKind kind = scene.restitution_model.kind;
  return kind == RestitutionModelKind::kViscoelastic || (kind != RestitutionModelKind::kConstant && !scene.isElastic());
}

/// The rotation model's own range: every finite body's momentum and kinetic energy in the
/// wall's frame (the lab frame without a wall), and the bounds it forms from them, are doubles.
bool rotationInRange(const Scene& scene) {
  std::optional<double> frame;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (scene.isWall(i)) frame = scene.velocities[i];
  }
  const double frame_velocity = frame.value_or(0.0);
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (scene.isWall(i)) continue;
    const double m = scene.masses[i], v = scene.velocities[i], relative = v - frame_velocity;
    if (!std::isfinite(relative) || !std::isfinite(m * v) || !std::isfinite(m * relative * relative) ||
        !std::isfinite(m * (4.0 * std::fabs(v) + 4.0 * std::fabs(frame_velocity)))) {
      return false;
    }
  }
  for (std::size_t p = 0; p + 1 < scene.size(); ++p) {
    if (!std::isfinite(2.0 * (std::fabs(scene.velocities[p]) + std::fabs(scene.velocities[p + 1])))) return false;
  }
  return true;
}

/// Three elastic bodies, at most one wall, not on a ring: the rotation model's scenes when
/// they lie in its range (rotationInRange).
bool isElasticTriple(const Scene& scene) {
  return scene.size() == 3 && !scene.isRing() && scene.isElastic() && scene.wallCount() < 2;
}

std::string restitutionModelText(const Scene& scene) {
  const RestitutionModel& model = scene.restitution_model;
  switch (model.kind) {
    case RestitutionModelKind::kTc:
      return "the TC model (t_c = " + std::to_string(model.tc) + " s: an impact is elastic unless both bodies' last "
             "impacts are more than t_c ago)";
    case RestitutionModelKind::kThreshold:
      return "the threshold law (e = 1 below an approach speed of " + std::to_string(model.elastic_below) + " m/s)";
    case RestitutionModelKind::kViscoelastic:
      return "the viscoelastic law e(v) = 1 - C1 (v/v*)^(1/5) + C2 (v/v*)^(2/5) (v* = " +
             std::to_string(model.viscoelastic_speed) + " m/s)";
    case RestitutionModelKind::kConstant: break;
  }
  return "a constant e per pair";
}

/// Walls at both ends that do not move apart, and no pair that can stick (e = 0).
bool confinedForever(const Scene& scene) {
  if (scene.size() < 3 || scene.wallCount() != 2) return false;
  if (scene.velocities.back() < scene.velocities.front()) return false;  // the walls separate
  for (std::size_t p = 0; p < scene.pairCount(); ++p) {
    if (scene.restitutionOf(p) == 0.0) return false;
  }
  return true;
}

bool everyPairSticks(const Scene& scene) {
  for (std::size_t p = 0; p < scene.pairCount(); ++p) {
    if (scene.restitutionOf(p) != 0.0) return false;
  }
  return true;
}

bool equalFiniteMasses(const Scene& scene) {
  if (scene.wallCount() > 0) return false;
  return std::all_of(scene.masses.begin(), scene.masses.end(), [&](double m) { return m == scene.masses[0]; });
}

/// The one-line reason of each model.
std::string modelReason(ModelKind kind, const Scene& scene) {
  switch (kind) {
    case ModelKind::kNoCollisions:
      return scene.size() == 1 ? "a single body never collides"
                               : "no pair approaches (v_p >= v_p+1 for every pair), so the bodies only move apart";
    case ModelKind::kTwoWallsInfinite:
      return "two walls that do not move apart confine the bodies, and with every e > 0 they collide forever: "
             "infinitely many impacts (a run stops at its cap)";
    case ModelKind::kBoxInfinite:
      return "a box: walls at both ends that do not move apart confine the bodies between them, and with every "
             "e > 0 they collide forever: infinitely many impacts, with no count to predict; the exact event engine "
             "simulates them up to the run's cap";
    case ModelKind::kTwoBody: return "two bodies meet at most once: one impact in closed form";
    case ModelKind::kThreeBodyRotation:
      return "three elastic bodies: the paper's rotation model gives the exact count and state in O(1)";
    case ModelKind::kGhosts:
      if (scene.isRing()) {
        return "equal masses on a ring exchange velocities, so the bodies move like ghosts passing through each other "
               "round the ring: the impacts by time t are the ghosts' crossings by t (ringCrossingsBy), and ghosts of "
               "different velocities cross again every L / |u_i - u_j|: infinitely many impacts (a run stops at its cap)";
      }
      return "equal masses exchange velocities, so the bodies move like ghosts passing through each other: "
             "the count is the number of inversions and the final velocities are the initial ones sorted";
    case ModelKind::kThreeBodySpiral:
      return (scene.restitutionOf(0) == scene.restitutionOf(1)
                  ? std::string("three bodies with one e < 1: the AB/BC cycle is a spiral (e > r_c) or may collapse "
                                "(e <= r_c); count, state and collapse from the 2x2 cycle map")
                  : std::string("three bodies with two e > 0 (AB and BC): the AB/BC cycle map has determinant e_AB e_BC; "
                                "a spiral or a collapse, decided by the same cone test; count, state and collapse from "
                                "the 2x2 cycle map (r_c is defined for one e)")) +
             (scene.wallCount() == 1 ? "; the wall is the outer body of infinite mass (k = 1 + e at the wall, "
                                       "cos^2 alpha = m/(m_B + m) of the two bodies), and a collapse ends on the wall"
                                     : "");
    case ModelKind::kSticky:
      return "every pair sticks (e = 0): a body that hits a group joins it, so the final groups are the blocks of the "
             "weighted isotonic regression of the initial velocities (pool-adjacent-violators, O(N)), each at its "
             "momentum over its mass (a wall's group at rest with the wall); each impact joins two groups, so the count "
             "is N - groups when no three bodies meet at once; the engine runs to tell (three bodies meeting at once stop it "
             "with MULTIPLE_COLLISION)";
    case ModelKind::kEventEngine: break;
  }
  if (restitutionModelActs(scene)) {
    return "the restitution of each impact follows " + restitutionModelText(scene) +
           ": no count formula exists, so the exact event engine simulates every impact";
  }
  if (isElasticTriple(scene)) {
    return "three elastic bodies whose momenta or kinetic energies in the wall's frame overflow a double, beyond the "
           "rotation model's range: the exact event engine simulates every impact";
  }
  if (scene.isRing()) {
    return "no count formula exists for " + std::to_string(scene.size()) +
           " bodies on a ring with these masses and restitution: the exact event engine simulates every impact "
           "(body N-1 meets body 0 across the seam)";
  }
  if (scene.size() == 3 && scene.wallCount() < 2 && scene.restitutionOf(0) != scene.restitutionOf(1)) {
    return "three bodies with two different e, one of them 0 (a pair that sticks): the exact event engine simulates "
           "every impact";
  }
  return "no count formula exists for " + std::to_string(scene.size()) +
         " bodies with these masses, walls and restitution: the exact event engine simulates every impact";
}

ModelKind chooseKind(const Scene& scene) {
  const std::size_t n = scene.size();
  if (n == 1 || !anyApproaching(scene)) return ModelKind::kNoCollisions;
  if (confinedForever(scene)) return n == 3 ? ModelKind::kTwoWallsInfinite : ModelKind::kBoxInfinite;
  if (restitutionModelActs(scene)) return ModelKind::kEventEngine;
  if (scene.isRing()) return equalFiniteMasses(scene) && scene.isElastic() ? ModelKind::kGhosts : ModelKind::kEventEngine;
  if (n == 2) return ModelKind::kTwoBody;
  if (isElasticTriple(scene)) return rotationInRange(scene) ? ModelKind::kThreeBodyRotation : ModelKind::kEventEngine;
  if (n == 3 && scene.wallCount() < 2 && !scene.isWall(1) &&
      (scene.restitutionOf(0) == scene.restitutionOf(1) ||
       (scene.restitutionOf(0) > 0.0 && scene.restitutionOf(1) > 0.0))) {
    return ModelKind::kThreeBodySpiral;
  }
  if (equalFiniteMasses(scene) && scene.isElastic()) return ModelKind::kGhosts;
  if (everyPairSticks(scene) && !(scene.wallCount() == 2 && scene.velocities.back() > scene.velocities.front())) {
    return ModelKind::kSticky;  // two walls that close in would squeeze a group between them
  }
  return ModelKind::kEventEngine;
}

Prediction base(ModelKind kind, const Scene& scene) {
  Prediction prediction;
  prediction.kind = kind;
  prediction.reason = modelReason(kind, scene);
  return prediction;
}

/// Merges two descending runs of `from` into `to`, counting the inversions between them.
std::uint64_t mergeCounting(const double* from, std::size_t begin, std::size_t middle, std::size_t end, double* to) {
  std::uint64_t inversions = 0;
  std::size_t i = begin, j = middle, out = begin;
  while (i < middle && j < end) {
    if (from[i] >= from[j]) {
      to[out++] = from[i++];
    } else {
      inversions += middle - i;  // every remaining earlier value is below this later one
      to[out++] = from[j++];
    }
  }
  while (i < middle) to[out++] = from[i++];
  while (j < end) to[out++] = from[j++];
  return inversions;
}

using spiral_detail::Rational;

/// Which pair hits first (0 = AB, 1 = BC), exactly; -1 when none approaches.
int firstPair(const Scene& scene, const Rational& a, const Rational& c) {
  if (a > 0 && c > 0) {  // both approach: the earlier contact (a tie is rejected by validate())
    const Rational t_ab = (Rational(scene.positions[0]) - scene.positions[1]) / a;
    const Rational t_bc = (Rational(scene.positions[1]) - scene.positions[2]) / c;
    return t_ab < t_bc ? 0 : 1;
  }
  return a > 0 ? 0 : (c > 0 ? 1 : -1);
}

/// Velocities [m/s] relative to the frame (the centre of mass, or the wall) from the approach
/// speeds (a, c) = (v_B - v_A, v_C - v_B), exactly: the frame's body (a wall) at 0.
std::array<Rational, 3> relativeVelocities(const spiral_detail::Cycle& cy, const Rational& a, const Rational& c) {
  const double* m = cy.m;
  Rational w_a = cy.wall_a ? Rational(0)
                 : cy.wall_c ? Rational(-(a + c))
                             : Rational(-(Rational(m[1]) * a + Rational(m[2]) * (a + c)) /
                                        (Rational(m[0]) + Rational(m[1]) + Rational(m[2])));
  return {w_a, w_a + a, w_a + a + c};
}

/// Kinetic energy [J] of the finite bodies at velocities w, exactly.
Rational kineticEnergy(const spiral_detail::Cycle& cy, const std::array<Rational, 3>& w) {
  Rational sum = 0;
  for (int k = 0; k < 3; ++k) {
    if (!(k == 0 && cy.wall_a) && !(k == 2 && cy.wall_c)) sum += Rational(cy.m[k]) * w[k] * w[k] / 2;
  }
  return sum;
}

/// Impacts up to which the spiral's end state is computed again in exact rationals: their size, and
/// the cost of each reduction, grow with every impact; beyond, the walk's end state stands, flagged.
constexpr std::uint64_t kExactSpiralStateLimit = 64;

/// (a, c) after `count` impacts from the first pair `first`, exactly: the cycle's 2x2 map
/// (first pair, then the other) to the power count / 2 by repeated squaring, then the first
/// pair's map once more for an odd count. The power is taken in integers over a common
/// denominator (rationals would reduce by a gcd at every product); the numbers grow
/// linearly with count.
void exactStateAfter(const spiral_detail::Cycle& cycle, int first, std::uint64_t count, Rational& a, Rational& c) {
  using boost::multiprecision::cpp_int;
  const spiral_detail::Maps<Rational> maps(cycle);
  // The cycle's matrix, column by column: the images of (1, 0) and (0, 1).
  std::array<Rational, 4> cycle_map{1, 0, 0, 1};  // m00, m10, m01, m11
  maps.apply(first, cycle_map[0], cycle_map[1]), maps.apply(1 - first, cycle_map[0], cycle_map[1]);
  maps.apply(first, cycle_map[2], cycle_map[3]), maps.apply(1 - first, cycle_map[2], cycle_map[3]);
  cpp_int common = 1;
  for (const Rational& x : cycle_map) common = lcm(common, denominator(x));
  std::array<cpp_int, 4> base, power{1, 0, 0, 1};
  for (int k = 0; k < 4; ++k) base[k] = numerator(cycle_map[k]) * (common / denominator(cycle_map[k]));
  const auto times = [](const std::array<cpp_int, 4>& x, const std::array<cpp_int, 4>& y) {
    return std::array<cpp_int, 4>{x[0] * y[0] + x[2] * y[1], x[1] * y[0] + x[3] * y[1], x[0] * y[2] + x[2] * y[3],
                                  x[1] * y[2] + x[3] * y[3]};
  };
  cpp_int scale = 1;  // common^(count / 2)
  for (std::uint64_t n = count / 2; n != 0; n >>= 1) {
    if (n & 1) power = times(power, base), scale *= common;
    if (n > 1) base = times(base, base), common *= common;
  }
  const Rational a_next = (Rational(power[0]) * a + Rational(power[2]) * c) / scale;
  c = (Rational(power[1]) * a + Rational(power[3]) * c) / scale;
  a = a_next;
  if (count % 2 == 1) maps.apply(first, a, c);
}

/// mantissa * 2^exponent, exactly; 0 below 2^-1200, far under every double (a spiral's
/// relative speeds after 10^8 impacts are 2^-10^8 of the start's).
Rational scaledRational(double mantissa, long exponent) {
  if (exponent < -1200) return 0;
  const boost::multiprecision::cpp_int power = boost::multiprecision::cpp_int(1) << static_cast<unsigned>(std::labs(exponent));
  return exponent >= 0 ? Rational(mantissa) * power : Rational(mantissa) / power;
}

Rational weightedMean(const double m[3], const std::vector<double>& q) {
  return (Rational(m[0]) * q[0] + Rational(m[1]) * q[1] + Rational(m[2]) * q[2]) /
         (Rational(m[0]) + Rational(m[1]) + Rational(m[2]));
}

}  // namespace

const char* modelKindName(ModelKind kind) {
  switch (kind) {
    case ModelKind::kNoCollisions: return "no_collisions";
    case ModelKind::kTwoWallsInfinite: return "two_walls_infinite";
    case ModelKind::kTwoBody: return "two_body";
    case ModelKind::kThreeBodyRotation: return "three_body_rotation";
    case ModelKind::kGhosts: return "ghosts";
    case ModelKind::kEventEngine: return "event_engine";
    case ModelKind::kThreeBodySpiral: return "three_body_spiral";
    case ModelKind::kBoxInfinite: return "box_infinite";
    case ModelKind::kSticky: return "sticky";
  }
  return "unknown";
}

ModelChoice chooseModel(const Scene& scene) {
  const ModelKind kind = chooseKind(scene);
  return {kind, modelReason(kind, scene)};
}

Prediction predictNoCollisions(const Scene& scene) {
  Prediction prediction = base(ModelKind::kNoCollisions, scene);
  prediction.impact_count = 0;
  prediction.final_velocities = scene.velocities;
  return prediction;
}

Prediction predictTwoWalls(const Scene& scene) {
  Prediction prediction = base(chooseKind(scene), scene);
  prediction.infinite = true;
  return prediction;
}

TwoBodyImpact exactTwoBodyImpact(const Scene& scene) {
  using spiral_detail::Rational;
  const auto& x = scene.positions;
  const auto& v = scene.velocities;
  // Everything exactly in rationals from the input doubles, each result rounded once, so any
  // mass ratio is exact. The centre-of-mass velocity V is a wall's velocity when one is a
  // wall; v' = (1 + e) V - e v; heat = mu (1 - e^2) (v_1 - v_0)^2 / 2, mu the reduced mass.
  const Rational re = scene.restitutionOf(0);
  const Rational v0 = v[0], v1 = v[1];
  Rational centre, reduced;
  if (scene.isWall(0) || scene.isWall(1)) {
    const std::size_t wall = scene.isWall(0) ? 0 : 1;
    centre = Rational(v[wall]);
    reduced = Rational(scene.masses[1 - wall]);
  } else {
    const Rational m0 = scene.masses[0], m1 = scene.masses[1];
    centre = (m0 * v0 + m1 * v1) / (m0 + m1);
    reduced = m0 * m1 / (m0 + m1);
  }
  const Rational time = (Rational(x[0]) - x[1]) / (v1 - v0);
  const Rational after[2] = {scene.isWall(0) ? v0 : Rational((1 + re) * centre - re * v0),
                             scene.isWall(1) ? v1 : Rational((1 + re) * centre - re * v1)};
  const Rational heat = reduced * (1 - re * re) * (v1 - v0) * (v1 - v0) / 2;
  Rational gained[2];
  for (int k = 0; k < 2; ++k) {
    if (!scene.isWall(k)) gained[k] = Rational(scene.masses[k]) * (after[k] * after[k] - v[k] * Rational(v[k])) / 2;
  }
  for (int k = 0; k < 2; ++k) {
    if (scene.isWall(k)) gained[k] = -(gained[1 - k] + heat);  // as the engine's record: the entries and the heat sum to 0
  }
  TwoBodyImpact impact;
  impact.time = detail::nearestDouble(time);
  impact.position = detail::nearestDouble(Rational(x[0]) + time * v0);
  for (int k = 0; k < 2; ++k) {
    impact.velocities_after[k] = scene.isWall(k) ? v[k] : detail::nearestDouble(after[k]);
    impact.energy_gained[k] = detail::nearestDouble(gained[k]);
  }
  impact.energy_lost = detail::nearestDouble(heat);
  return impact;
}

Prediction predictTwoBody(const Scene& scene) {
  Prediction prediction = base(ModelKind::kTwoBody, scene);
  prediction.final_velocities = scene.velocities;
  prediction.impact_count = 0;
  if (!(scene.velocities[0] < scene.velocities[1])) return prediction;
  const TwoBodyImpact impact = exactTwoBodyImpact(scene);
  prediction.impact_count = 1;
  prediction.first_pair_index = 0;
  prediction.impact_time = impact.time;
  prediction.impact_position = impact.position;
  prediction.final_velocities = {impact.velocities_after[0], impact.velocities_after[1]};
  prediction.energy_lost = impact.energy_lost;
  return prediction;
}

Prediction predictGhosts(const Scene& scene) {
  Prediction prediction = base(ModelKind::kGhosts, scene);
  if (scene.isRing()) {  // some pair approaches, so two ghosts differ in velocity: they meet forever
    prediction.infinite = true;
    return prediction;
  }
  prediction.impact_count = countInversions(scene.velocities);
  prediction.final_velocities = scene.velocities;
  // The fastest rightward ends on the right, at index 0.
  std::sort(prediction.final_velocities.begin(), prediction.final_velocities.end(), std::greater<double>());
  return prediction;
}

Prediction predictSticky(const Scene& scene) {
  using spiral_detail::Rational;
  Prediction prediction = base(ModelKind::kSticky, scene);
  /// A group of adjacent bodies first..last: its momentum [kg m/s] and mass [kg] exactly, or
  /// the velocity [m/s] of the wall it holds (infinite mass).
  struct Group {
    std::size_t first, last;
    Rational momentum, mass;
    std::optional<double> wall_velocity;
  };
  // v_A < v_B (A of lower index, on the right) means B catches A up.
  const auto approaches = [](const Group& a, const Group& b) {
    if (a.wall_velocity && b.wall_velocity) return *a.wall_velocity < *b.wall_velocity;
    if (a.wall_velocity) return Rational(*a.wall_velocity) * b.mass < b.momentum;
    if (b.wall_velocity) return a.momentum < Rational(*b.wall_velocity) * a.mass;
    return a.momentum * b.mass < b.momentum * a.mass;
  };
  std::vector<Group> groups;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    Group g{i, i, 0, 0, std::nullopt};
    if (scene.isWall(i)) {
      g.wall_velocity = scene.velocities[i];
    } else {
      g.mass = scene.masses[i];
      g.momentum = Rational(scene.masses[i]) * scene.velocities[i];
    }
    while (!groups.empty() && approaches(groups.back(), g)) {  // they meet and stick: pool them
      Group& right = groups.back();
      g.first = right.first;
      g.momentum += right.momentum, g.mass += right.mass;
      if (right.wall_velocity) g.wall_velocity = right.wall_velocity;  // chooseKind: never two walls in one group
      groups.pop_back();
    }
    groups.push_back(std::move(g));
  }
  prediction.impact_count = scene.size() - groups.size();
  prediction.final_velocities.resize(scene.size());
  Rational heat = 0;
  for (const Group& g : groups) {
    const Rational velocity = g.wall_velocity ? Rational(*g.wall_velocity) : g.momentum / g.mass;
    const double rounded = static_cast<double>(velocity);
    for (std::size_t i = g.first; i <= g.last; ++i) {
      prediction.final_velocities[i] = scene.isWall(i) ? scene.velocities[i] : rounded;
      if (!scene.isWall(i)) {  // the body's kinetic energy in its group's frame turns into heat
        const Rational relative = Rational(scene.velocities[i]) - velocity;
        heat += Rational(scene.masses[i]) * relative * relative / 2;
      }
    }
  }
  prediction.energy_lost = static_cast<double>(heat);
  return prediction;
}

Prediction predictThreeBodySpiral(const Scene& scene) {
  using namespace spiral_detail;
  Prediction prediction = base(ModelKind::kThreeBodySpiral, scene);
  Cycle cycle{{scene.masses[0], scene.masses[1], scene.masses[2]}, scene.restitutionOf(0), scene.restitutionOf(1)};
  cycle.wall_a = scene.isWall(0), cycle.wall_c = scene.isWall(2);
  const std::optional<int> wall = cycle.wall_a ? std::optional<int>(0) : (cycle.wall_c ? std::optional<int>(2) : std::nullopt);
  const double* m = cycle.m;
  const detail::RoundedAngles angles = detail::roundedAngles({m[0], m[1], m[2]});
  prediction.alpha = angles.alpha;
  if (cycle.e == cycle.eBC()) prediction.critical_restitution = angles.critical_restitution;  // a value of the one e
  if (cycle.complexEigenvalues()) {
    prediction.spiral_angle =
        detail::roundedSpiralAngle(cycle.exactTrace(), Rational(cycle.e) * Rational(cycle.eBC()));
  }
  const auto& v = scene.velocities;
  const Rational a0 = Rational(v[1]) - v[0], c0 = Rational(v[2]) - v[1];
  // The frame: the centre of mass, or the wall (which the bodies follow after a collapse).
  const Rational centre = wall ? Rational(v[*wall]) : weightedMean(m, v);
  const Rational heat0 = kineticEnergy(cycle, relativeVelocities(cycle, a0, c0));
  // Every body at the frame's velocity, all the relative motion turned into heat.
  const auto together = [&] {
    prediction.final_velocities.assign(3, detail::nearestDouble(centre));
    if (wall) prediction.final_velocities[*wall] = v[*wall];
    prediction.energy_lost = detail::nearestDouble(heat0);
  };
  const int first = firstPair(scene, a0, c0);
  Walk walked;
  if (first < 0) {
    walked = {WalkEnd::kFinished, 0, 0.0, 0.0, 0};
  } else if (cycle.e == 0.0) {  // the first pair sticks; a hit on that cluster makes all three one
    Rational a = a0, c = c0;
    Maps<Rational>(cycle).apply(first, a, c);
    walked = {WalkEnd::kFinished, 1, 0.0, 0.0, 0};
    if ((first == 0 ? c : a) > 0) {  // the third body hits the cluster and sticks: all three move at V
      prediction.impact_count = 2;
      together();
      return prediction;
    }
  } else {
    walked = walkExactly(cycle, first, a0, c0);
  }
  if (walked.end == WalkEnd::kUndecided) {
    prediction.reason += "; undecided: the walk needs more impacts than it may take exactly (run the engine)";
    return prediction;
  }
  if (walked.end == WalkEnd::kEndless) {
    prediction.infinite = true;
    prediction.reason += "; the approach speeds start on the cycle's slower eigenvector, which stays in the cone: "
                         "infinitely many impacts in an infinite time, no collapse (spiral.h, slowEigenvector)";
    return prediction;
  }
  if (walked.end == WalkEnd::kCollapse) {
    prediction.collapsed = true;
    prediction.infinite = true;
    together();
    const Rational dv[2] = {a0, c0};
    const Rational db[2] = {Rational(scene.positions[1]) - scene.positions[0],
                            Rational(scene.positions[2]) - scene.positions[1]};
    const Bounded time = collapseTimeBounded(cycle, first, dv, db);
    // The meeting point start + V t from the exact start and V, in 100 digits: the two terms
    // of a heavy-light-heavy collapse nearly cancel, and their difference is rounded once.
    const Rational start = wall ? Rational(scene.positions[*wall]) : weightedMean(m, scene.positions);
    const auto wide = [](const Rational& r) { return Float100(numerator(r)) / Float100(denominator(r)); };
    const Float100 velocity = wide(centre), eps = ldexp(Float100(1), -320);
    const Float100 point = wide(start) + velocity * time.value;
    const Float100 point_error = abs(velocity) * time.error + 8 * eps * (abs(wide(start)) + abs(velocity * time.value));
    const auto certified_time = detail::certifiedNearest(time.value, time.error);
    const auto certified_point = detail::certifiedNearest(point, point_error);
    prediction.collapse_time = certified_time.value_or(static_cast<double>(time.value));
    prediction.collapse_position = certified_point.value_or(static_cast<double>(point));
    if (!certified_time) prediction.uncertified.push_back("collapse_time");
    if (!certified_point) prediction.uncertified.push_back("collapse_position");
    return prediction;
  }
  prediction.impact_count = walked.count;
  // The state after the count's impacts, exactly: the maps in rationals from the start (short
  // walks, the spiral's usual case), else the walk's end state (to its rounding, flagged).
  Rational a = a0, c = c0;
  if (walked.count <= kExactSpiralStateLimit) {
    exactStateAfter(cycle, first, walked.count, a, c);
  } else {
    a = scaledRational(walked.a, walked.exponent), c = scaledRational(walked.c, walked.exponent);
    prediction.uncertified.push_back("predicted_final_velocities");
    prediction.uncertified.push_back("energy_lost");
  }
  const std::array<Rational, 3> w = relativeVelocities(cycle, a, c);
  for (int k = 0; k < 3; ++k) {
    prediction.final_velocities.push_back(wall && *wall == k ? v[k] : detail::nearestDouble(centre + w[k]));
  }
  prediction.energy_lost = detail::nearestDouble(heat0 - kineticEnergy(cycle, w));
  return prediction;
}

Prediction predictThreeBodyRotation(const Scene& scene) {
  Prediction prediction = base(ModelKind::kThreeBodyRotation, scene);
  fillRotationPrediction(scene, prediction);
  return prediction;
}

std::optional<Prediction> predict(const Scene& scene) {
  switch (chooseKind(scene)) {
    case ModelKind::kNoCollisions:
      if (isElasticTriple(scene) && rotationInRange(scene)) {
        // Three elastic bodies that never meet: the rotation model's values describe them too
        // (its count 0, its angles and the paper's values), and its run reports them.
        Prediction prediction = predictThreeBodyRotation(scene);
        prediction.kind = ModelKind::kNoCollisions;
        prediction.reason = modelReason(ModelKind::kNoCollisions, scene);
        return prediction;
      }
      return predictNoCollisions(scene);
    case ModelKind::kTwoWallsInfinite:
    case ModelKind::kBoxInfinite: return predictTwoWalls(scene);
    case ModelKind::kTwoBody: return predictTwoBody(scene);
    case ModelKind::kGhosts: return predictGhosts(scene);
    case ModelKind::kThreeBodySpiral: return predictThreeBodySpiral(scene);
    case ModelKind::kSticky: return predictSticky(scene);
    case ModelKind::kThreeBodyRotation: return predictThreeBodyRotation(scene);
    case ModelKind::kEventEngine: break;
  }
  return std::nullopt;
}

std::optional<WallPeriod> wallToWallPeriod(const Scene& scene) {
  if (scene.size() != 3 || scene.isRing() || !scene.isWall(0) || !scene.isWall(2) || scene.isWall(1) ||
      !scene.isElastic()) {
    return std::nullopt;
  }
  const auto& v = scene.velocities;
  if (v[0] != 0 || v[2] != 0 || v[1] == 0 || !std::isfinite(v[1])) return std::nullopt;
  using spiral_detail::Rational;
  const Rational span = Rational(scene.positions[0]) - scene.positions[2];
  const double time = detail::nearestDouble(2 * span / abs(Rational(v[1])));
  if (!(time > 0) || !std::isfinite(time)) return std::nullopt;
  return WallPeriod{time, 2};
}

std::uint64_t ringCrossingsBy(const Scene& scene, double t) {
  const double length = scene.ring;
  std::uint64_t crossings = 0;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    for (std::size_t j = i + 1; j < scene.size(); ++j) {
      // Ghost i is ahead of ghost j by d in (0, L) (x_i > x_j); their gap changes at w.
      const double d = scene.positions[i] - scene.positions[j], w = scene.velocities[i] - scene.velocities[j];
      if (w < 0) {  // i is caught up at d + w t = 0, -L, -2L, ...
        if (-w * t >= d) crossings += static_cast<std::uint64_t>(std::floor((-w * t - d) / length)) + 1;
      } else if (w > 0) {  // i laps j from behind at d + w t = L, 2L, ...
        crossings += static_cast<std::uint64_t>(std::floor((d + w * t) / length));
      }
    }
  }
  return crossings;
}

std::uint64_t countInversions(const std::vector<double>& velocities) {
  const std::size_t n = velocities.size();
  std::vector<double> a = velocities, b(n);
  std::uint64_t inversions = 0;
  for (std::size_t width = 1; width < n; width *= 2) {
    for (std::size_t begin = 0; begin < n; begin += 2 * width) {
      const std::size_t middle = std::min(begin + width, n), end = std::min(begin + 2 * width, n);
      inversions += mergeCounting(a.data(), begin, middle, end, b.data());
    }
    a.swap(b);
  }
  return inversions;
}

}  // namespace core
}  // namespace collision_lab
