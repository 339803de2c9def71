#include "collision_lab/core/nbody/scene.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_int.hpp>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/precision.h"

namespace collision_lab {
namespace core {

namespace {

using Rational = boost::multiprecision::cpp_rational;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Beyond this finite-mass ratio the engine's 100-digit tier loses its margin (its error
/// bounds, spread over the light bodies, exceed what it must decide, and the runs stop out of
/// range); a body that much heavier is a wall to every digit that matters. Three elastic
/// bodies are answered by the rotation model, exact at any ratio, and have no such limit.
constexpr double kMaxMassRatio = 1e100;

/// Shortest text that reads back as the same double; any NaN is "NaN" and a zero is "0",
/// never signed.
std::string formatValue(double value) {
  if (std::isnan(value)) return "NaN";
  if (value == 0) return "0";
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::string(buffer, end);
}

std::string indexedField(const char* list, std::size_t i) { return std::string(list) + "[" + std::to_string(i) + "]"; }

/// `field` says where; the message says what is wrong there without repeating it.
ValidationError makeError(Reason reason, const std::string& field, const std::string& message) {
  return ValidationError{reason, field, message};
}

std::optional<ValidationError> checkShape(const Scene& scene) {
  const std::size_t n = scene.masses.size();
  if (scene.positions.size() != n || scene.velocities.size() != n) {
    return makeError(Reason::kUnequalLengths, "masses",
                     "the lists have different lengths (masses " + std::to_string(n) + ", positions " +
                         std::to_string(scene.positions.size()) + ", velocities " +
                         std::to_string(scene.velocities.size()) + "); give one mass, position and velocity per body");
  }
  if (n == 0) {
    return makeError(Reason::kEmptyScene, "masses", "the scene has no bodies; give at least one mass, position and velocity");
  }
  const std::size_t count = scene.restitution.size(), pairs = scene.contactCount();
  if (count != 0 && count != 1 && count != pairs) {
    return makeError(Reason::kRestitutionCount, "restitution",
                     std::to_string(count) + " values for " + std::to_string(pairs) +
                         " pairs; give none (elastic), one for every pair, or one per pair (" +
                         (scene.isRing() ? "N on a ring = " : "N-1 = ") + std::to_string(pairs) + ")");
  }
  for (std::size_t i = 0; i < count; ++i) {
    const double e = scene.restitution[i];
    if (!(e >= 0.0 && e <= 1.0)) {
      return makeError(Reason::kRestitutionOutOfRange, indexedField("restitution", i),
                       "e = " + formatValue(e) + " is not a coefficient of restitution; it must lie in [0, 1] (1 = elastic)");
    }
  }
  return std::nullopt;
}

std::optional<ValidationError> checkMasses(const Scene& scene) {
  const std::size_t n = scene.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double m = scene.masses[i];
    if (std::isnan(m)) {
      return makeError(Reason::kNonFiniteValue, indexedField("masses", i),
                       "m_" + bodyName(i) + " is NaN; a mass must be a positive number in kg, or inf for a wall");
    }
    if (!(m > 0.0)) {
      return makeError(Reason::kNonPositiveMass, indexedField("masses", i),
                       "m_" + bodyName(i) + " is " + formatValue(m) + " kg; a mass must be positive");
    }
    if (std::isinf(m) && i != 0 && i + 1 != n) {
      return makeError(Reason::kWallNotAtEnd, indexedField("masses", i),
                       "the mass of " + bodyName(i) + " is inf, but a wall may only be the first or the last body; "
                       "give it a finite mass in kg");
    }
  }
  if (n == 2 && scene.isWall(0) && scene.isWall(1)) {
    return makeError(Reason::kTwoWalls, "masses", "both bodies are walls (inf) with no body between them; give one a finite mass");
  }
  if (n == 3 && scene.isElastic() && !scene.isRing()) return std::nullopt;  // the rotation model: any ratio
  if (n == 2 && !scene.isRing()) return std::nullopt;  // two bodies: one impact in closed form at any ratio
  double lightest = kInf, heaviest = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (scene.isWall(i)) continue;
    lightest = std::min(lightest, scene.masses[i]);
    heaviest = std::max(heaviest, scene.masses[i]);
  }
  if (heaviest > 0.0 && !(heaviest / lightest <= kMaxMassRatio)) {
    return makeError(Reason::kOverflow, "masses",
                     "the ratio of the largest to the smallest finite mass exceeds 1e100 (" + formatValue(heaviest) +
                         " / " + formatValue(lightest) + " kg); make the heavy body a wall (inf) instead");
  }
  return std::nullopt;
}

/// The restitution model's parameter, and viscoelastic only with an elastic restitution
/// list (its e(v) replaces the pairs' e).
std::optional<ValidationError> checkRestitutionModel(const Scene& scene) {
  const RestitutionModel& model = scene.restitution_model;
  const auto positive = [](double value) { return value > 0.0 && std::isfinite(value); };
  switch (model.kind) {
    case RestitutionModelKind::kConstant: return std::nullopt;
    case RestitutionModelKind::kTc:
      if (positive(model.tc)) return std::nullopt;
      return makeError(Reason::kRestitutionModel, "tc",
                       "t_c = " + formatValue(model.tc) + " s; the TC model needs a positive finite time in s");
    case RestitutionModelKind::kThreshold:
      if (positive(model.elastic_below)) return std::nullopt;
      return makeError(Reason::kRestitutionModel, "elastic_below",
                       "v_0 = " + formatValue(model.elastic_below) +
                           " m/s; the threshold model needs a positive finite speed in m/s");
    case RestitutionModelKind::kViscoelastic:
      if (!positive(model.viscoelastic_speed)) {
        return makeError(Reason::kRestitutionModel, "viscoelastic_speed",
                         "v* = " + formatValue(model.viscoelastic_speed) +
                             " m/s; the viscoelastic model needs a positive finite speed in m/s");
      }
      if (scene.isElastic()) return std::nullopt;
      return makeError(Reason::kRestitutionModel, "restitution",
                       "the viscoelastic model gives every impact its e(v); leave restitution empty (or 1)");
  }
  return makeError(Reason::kRestitutionModel, "restitution_model",
                   std::to_string(static_cast<int>(model.kind)) + " is not a restitution model (0-3)");
}

/// A ring: a positive finite circumference, no wall, every position in [0, L).
std::optional<ValidationError> checkRing(const Scene& scene) {
  if (!scene.isRing()) return std::nullopt;
  const double length = scene.ring;
  if (!(length > 0.0 && std::isfinite(length))) {
    return makeError(Reason::kRing, "ring", "L = " + formatValue(length) + " m; a ring needs a positive finite circumference in m");
  }
  for (std::size_t p = 0; p < scene.contactCount(); ++p) {
    if (scene.restitutionOf(p) == 0.0) {
      return makeError(Reason::kRing, "restitution",
                       "e = 0 makes bodies stick into clusters, which a ring does not support; give every pair e > 0");
    }
  }
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (scene.isWall(i)) {
      return makeError(Reason::kRing, indexedField("masses", i),
                       "the mass of " + bodyName(i) + " is inf, but a ring has no walls; give it a finite mass in kg");
    }
    const double x = scene.positions[i];
    if (std::isfinite(x) && !(x >= 0.0 && x < length)) {
      return makeError(Reason::kRing, indexedField("positions", i),
                       "x_" + bodyName(i) + " = " + formatValue(x) + " m lies outside the ring's [0, " +
                           formatValue(length) + ") m");
    }
  }
  return std::nullopt;
}

std::optional<ValidationError> checkFinite(const std::vector<double>& values, const char* list, const char* symbol,
                                           const char* unit) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      return makeError(Reason::kNonFiniteValue, indexedField(list, i),
                       symbol + bodyName(i) + " is " + formatValue(values[i]) + "; a " + unit);
    }
  }
  return std::nullopt;
}

std::optional<ValidationError> checkOrder(const Scene& scene) {
  const auto& x = scene.positions;
  for (std::size_t i = 0; i + 1 < x.size(); ++i) {
    const std::string a = bodyName(i), b = bodyName(i + 1);
    if (x[i] == x[i + 1]) {
      return makeError(Reason::kPositionsCoincident, "positions",
                       "x_" + a + " = x_" + b + " = " + formatValue(x[i]) + " m; " + a + " and " + b + " must start apart");
    }
    if (!(x[i] > x[i + 1])) {
      return makeError(Reason::kPositionsNotOrdered, "positions",
                       "x_" + a + " = " + formatValue(x[i]) + " m is not greater than x_" + b + " = " +
                           formatValue(x[i + 1]) + " m; list the bodies right to left (strictly decreasing positions)");
    }
  }
  return std::nullopt;
}

/// Everything the engine forms must be representable: momenta, kinetic energies, gaps,
/// relative velocities and their sums.
std::optional<ValidationError> checkRange(const Scene& scene) {
  const auto& m = scene.masses;
  const auto& x = scene.positions;
  const auto& v = scene.velocities;
  double energy = 0.0, momentum = 0.0;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (scene.isWall(i)) continue;
    energy += m[i] * v[i] * v[i];
    momentum += m[i] * std::fabs(v[i]);
    if (!std::isfinite(energy) || !std::isfinite(momentum) || !std::isfinite(8.0 * v[i])) {
      const bool own = !std::isfinite(m[i] * v[i] * v[i]) || !std::isfinite(8.0 * v[i]);
      return makeError(Reason::kOverflow, indexedField("velocities", i),
                       std::string(own ? "" : "the total of the ") + "momentum or kinetic energy of " +
                           (own ? "" : "the bodies up to ") + bodyName(i) + " (m = " + formatValue(m[i]) +
                           " kg, v = " + formatValue(v[i]) + " m/s) overflows a double; rescale the units");
    }
  }
  for (std::size_t i = 0; i < scene.contactCount(); ++i) {
    const std::size_t j = scene.leftOf(i);
    if (!std::isfinite(x[i] - x[j] + (j == 0 ? scene.ring : 0.0)) ||
        !std::isfinite(4.0 * (std::fabs(v[i]) + std::fabs(v[j])))) {
      return makeError(Reason::kOverflow, "positions",
                       "the gap or relative velocity between " + bodyName(i) + " and " + bodyName(j) +
                           " overflows a double; rescale the units");
    }
  }
  return std::nullopt;
}

/// Three significant digits, for values that are approximate anyway.
std::string formatShort(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", value);
  return buffer;
}

/// Three significant digits of an exact value of any size (beyond the range of a double too).
std::string formatShort(const Rational& q) {
  return HighPrecision(HighPrecision(numerator(q)) / HighPrecision(denominator(q))).str(3);
}

/// The rotation model (three elastic bodies, the middle one finite, at most one wall)
/// reports its counts as 64-bit integers, and no start of these masses can have more
/// impacts than ceil(pi / alpha). Only a light B makes that many: the count grows like
/// pi sqrt(m / m_B) with m the lighter of A and C.
std::optional<ValidationError> checkCountFits(const Scene& scene) {
  if (scene.size() != 3 || !scene.isElastic() || scene.wallCount() == 2 || scene.isRing()) return std::nullopt;
  const std::array<double, 3> masses{scene.masses[0], scene.masses[1], scene.masses[2]};
  if (checkedMaxPossibleImpactCount(masses)) return std::nullopt;
  const double most = M_PI / anglesFor(masses).alpha;
  return makeError(Reason::kOverflow, "masses",
                   "these masses allow up to ceil(pi / alpha) = " +
                       (std::isfinite(most) ? formatShort(most) : std::string("1.8e+308 or more")) +
                       " collisions, more than 2^64 - 1 = 18446744073709551615, the largest count collision_lab "
                       "reports; the count grows like pi sqrt(m / m_B) with m = " +
                       formatValue(std::min(masses[0], masses[2])) +
                       " kg the lighter of A and C: make B heavier or that body lighter");
}

/// Contact pair p's first meeting time (the seam pair's left body at x_0 - L).
Rational exactTime(const Scene& scene, std::size_t p) {
  const std::size_t j = scene.leftOf(p);
  const Rational gap =
      Rational(scene.positions[p]) - Rational(scene.positions[j]) + (j == 0 ? Rational(scene.ring) : Rational(0));
  return gap / (Rational(scene.velocities[j]) - Rational(scene.velocities[p]));
}

std::optional<ValidationError> checkFirstContactExactly(const Scene& scene, const std::vector<std::size_t>& candidates,
                                                       double first);

/// The first contact, which certainly happens: not two contacts sharing a body at once, and
/// its time and every position then within the range of a double (later contacts beyond it
/// are the run's to report). Decided exactly for the given doubles.
std::optional<ValidationError> checkFirstContact(const Scene& scene) {
  const auto& x = scene.positions;
  const auto& v = scene.velocities;
  std::vector<double> time(scene.contactCount(), kInf);
  double first = kInf;
  bool approaching = false;
  for (std::size_t p = 0; p < time.size(); ++p) {
    const std::size_t j = scene.leftOf(p);
    if (!(v[p] < v[j])) continue;
    approaching = true;
    time[p] = (x[p] - x[j] + (j == 0 ? scene.ring : 0.0)) / (v[j] - v[p]);
    first = std::min(first, time[p]);
  }
  if (!approaching) return std::nullopt;
  // Each double time is within 3 ulps of the truth (or beyond the range of a double, inf);
  // exact rationals settle the near-ties. Only approaching pairs have a time.
  const double window = first * (1.0 + 0x1p-48) + 4.0 * std::numeric_limits<double>::denorm_min();
  std::vector<std::size_t> candidates;
  for (std::size_t p = 0; p < time.size(); ++p) {
    if (v[p] < v[scene.leftOf(p)] && time[p] <= window) candidates.push_back(p);
  }
  // One candidate shares a body with no other, and a time far inside the range in double
  // (within a few ulps of the exact one: no ring term, whose sum may cancel) cannot overflow:
  // its rationals, which cost as much as a short run, are needed only for a position at
  // the end of the range.
  constexpr double kFarInside = 1e300;
  if (candidates.size() == 1 && first <= kFarInside && (!scene.isRing() || scene.leftOf(candidates[0]) != 0)) {
    for (std::size_t i = 0; i < scene.size(); ++i) {
      if (!(std::fabs(x[i] + v[i] * first) <= 0x1p1020)) return checkFirstContactExactly(scene, candidates, first);
    }
    return std::nullopt;
  }
  return checkFirstContactExactly(scene, candidates, first);
}

/// checkFirstContact's exact part: `candidates` are the pairs that may come first (their
/// double times within the window of the earliest, `first` [s]).
std::optional<ValidationError> checkFirstContactExactly(const Scene& scene, const std::vector<std::size_t>& candidates,
                                                       double first) {
  const auto& x = scene.positions;
  const auto& v = scene.velocities;
  std::vector<Rational> exact;
  for (std::size_t p : candidates) exact.push_back(exactTime(scene, p));
  const std::size_t earliest_k = static_cast<std::size_t>(std::min_element(exact.begin(), exact.end()) - exact.begin());
  const Rational& earliest = exact[earliest_k];
  // Two contacts sharing a body: consecutive pairs, or on a ring the seam pair and pair 0.
  const std::size_t n = candidates.size();
  for (std::size_t k = 0; k < n && n >= 2; ++k) {
    const std::size_t p = candidates[k], next = (k + 1) % n;
    const bool shared = candidates[next] == p + 1 || (next == 0 && k == n - 1 && scene.leftOf(p) == 0 &&
                                                      candidates[0] == 0 && scene.size() > 2);
    if (shared && exact[k] == earliest && exact[next] == earliest) {
      return makeError(Reason::kTripleCollision, "positions",
                       bodyName(p) + ", " + bodyName(scene.leftOf(p)) + " and " +
                           bodyName(scene.leftOf(scene.leftOf(p))) +
                           " would meet at the same instant (t = " + formatShort(earliest) +
                           " s), a multiple collision whose outcome point masses do not define; move one of them");
    }
  }
  const std::size_t pair = candidates[earliest_k];
  const std::string contact = "the first contact, of " + bodyName(pair) + " and " + bodyName(scene.leftOf(pair)) + ", ";
  const Rational largest(std::numeric_limits<double>::max());
  if (earliest > largest) {
    return makeError(Reason::kOverflow, "positions",
                     contact + "would come at t = " + formatShort(earliest) +
                         " s, beyond the largest double (1.8e+308); a longer unit of time brings it into range");
  }
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (std::fabs(x[i] + v[i] * first) <= 0x1p1020) continue;  // far inside the range: no exact check needed
    const Rational position = Rational(x[i]) + Rational(v[i]) * earliest;
    if (abs(position) > largest) {
      return makeError(Reason::kOverflow, "positions",
                       contact + "at t = " + formatShort(earliest) + " s, would find " + bodyName(i) + " at " +
                           formatShort(position) +
                           " m, beyond the largest double (1.8e+308); a longer unit of length brings it into range");
    }
  }
  return std::nullopt;
}

}  // namespace

bool Scene::isWall(std::size_t body) const { return masses[body] == kInf; }

std::size_t Scene::wallCount() const {
  if (masses.empty()) return 0;
  if (masses.size() == 1) return isWall(0) ? 1 : 0;
  return (isWall(0) ? 1 : 0) + (isWall(masses.size() - 1) ? 1 : 0);
}

double Scene::restitutionOf(std::size_t pair) const {
  if (restitution.empty()) return 1.0;
  return restitution.size() == 1 ? restitution[0] : restitution[pair];
}

bool Scene::isElastic() const {
  return std::all_of(restitution.begin(), restitution.end(), [](double e) { return e == 1.0; });
}

const char* restitutionModelName(RestitutionModelKind kind) {
  switch (kind) {
    case RestitutionModelKind::kConstant: return "constant";
    case RestitutionModelKind::kTc: return "tc";
    case RestitutionModelKind::kViscoelastic: return "viscoelastic";
    case RestitutionModelKind::kThreshold: return "threshold";
  }
  return "unknown";
}

std::string bodyName(std::size_t body) {
  if (body < 26) return std::string(1, static_cast<char>('A' + body));
  return "#" + std::to_string(body);
}

namespace {

/// Bodies `right` and `left` as a pair: their names, joined by '-' unless both are letters.
std::string namesOfPair(std::size_t right, std::size_t left) {
  return bodyName(right) + (right < 26 && left < 26 ? "" : "-") + bodyName(left);
}

}  // namespace

std::string pairName(std::size_t pair) { return namesOfPair(pair, pair + 1); }

std::string impactPairName(std::size_t pair_index, std::size_t last_moved) {
  return last_moved < pair_index ? namesOfPair(pair_index, 0) : pairName(pair_index);
}

const char* reasonName(Reason reason) {
  switch (reason) {
    case Reason::kOk: return "OK";
    case Reason::kNonFiniteValue: return "NON_FINITE_VALUE";
    case Reason::kNonPositiveMass: return "NON_POSITIVE_MASS";
    case Reason::kTwoWalls: return "TWO_WALLS";
    case Reason::kInfiniteMiddleMass: return "INFINITE_MIDDLE_MASS";
    case Reason::kPositionsNotOrdered: return "POSITIONS_NOT_ORDERED";
    case Reason::kPositionsCoincident: return "POSITIONS_COINCIDENT";
    case Reason::kTripleCollision: return "TRIPLE_COLLISION";
    case Reason::kOverflow: return "OVERFLOW";
    case Reason::kUnequalLengths: return "UNEQUAL_LENGTHS";
    case Reason::kEmptyScene: return "EMPTY_SCENE";
    case Reason::kRestitutionOutOfRange: return "RESTITUTION_OUT_OF_RANGE";
    case Reason::kRestitutionCount: return "RESTITUTION_COUNT";
    case Reason::kWallNotAtEnd: return "WALL_NOT_AT_END";
    case Reason::kRestitutionModel: return "RESTITUTION_MODEL";
    case Reason::kRing: return "RING";
  }
  return "UNKNOWN";
}

std::optional<ValidationError> validate(const Scene& scene) {
  if (auto error = checkShape(scene)) return error;
  if (auto error = checkMasses(scene)) return error;
  if (auto error = checkRestitutionModel(scene)) return error;
  if (auto error = checkRing(scene)) return error;
  if (auto error = checkFinite(scene.positions, "positions", "x_", "position must be a finite number in m")) return error;
  if (auto error = checkFinite(scene.velocities, "velocities", "v_", "velocity must be a finite number in m/s")) return error;
  if (auto error = checkOrder(scene)) return error;
  if (auto error = checkRange(scene)) return error;
  if (auto error = checkCountFits(scene)) return error;
  return checkFirstContact(scene);
}

}  // namespace core
}  // namespace collision_lab
