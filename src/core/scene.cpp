#include "collision_lab/core/scene.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/precision.h"

namespace collision_lab {
namespace core {

namespace {

const char* const kParticleNames[3] = {"A", "B", "C"};

std::string indexedField(const char* vector_name, int i) {
  return std::string(vector_name) + "[" + std::to_string(i) + "]";
}

/// Shortest text that reads back as the same double; any NaN is "NaN" and a zero is "0",
/// never signed.
std::string formatValue(double value) {
  if (std::isnan(value)) return "NaN";
  if (value == 0) return "0";
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::string(buffer, end);
}

/// Three significant digits, for values that are approximate anyway.
std::string formatShort(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", value);
  return buffer;
}

/// `field` says where; the message says what is wrong there without repeating it (a
/// front end shows both, the CLI as "invalid <field> (<REASON>): <message>").
ValidationError makeError(Reason reason, const std::string& field, const std::string& message) {
  return ValidationError{reason, field, message};
}

bool isFiniteProduct(double a, double b) { return std::isfinite(a * b); }


}  // namespace

bool ThreeBodyScene::isWall(int i) const { return masses[i] == std::numeric_limits<double>::infinity(); }

double largestFiniteMass(const std::array<double, 3>& masses) {
  double largest = 0.0;
  for (double m : masses) {
    if (!std::isinf(m)) largest = std::max(largest, m);
  }
  return largest;
}

int ThreeBodyScene::wallIndex() const {
  if (isWall(kA)) return kA;
  if (isWall(kC)) return kC;
  return -1;
}

namespace {

std::optional<ValidationError> checkMasses(const ThreeBodyScene& scene) {
  for (int i = 0; i < 3; ++i) {
    const double m = scene.masses[i];
    const std::string field = indexedField("masses", i);
    if (std::isnan(m)) {
      return makeError(Reason::kNonFiniteValue, field,
                       std::string("m_") + kParticleNames[i] + " is NaN; a mass must be a positive number in kg, or inf for a wall");
    }
    if (!(m > 0.0)) {
      return makeError(Reason::kNonPositiveMass, field,
                       std::string("m_") + kParticleNames[i] + " is " + formatValue(m) + " kg; a mass must be positive");
    }
  }
  if (std::isinf(scene.masses[kB])) {
    return makeError(Reason::kInfiniteMiddleMass, "masses[1]",
                     "m_B is inf; only A or C may be a wall, B must have a finite mass");
  }
  if (std::isinf(scene.masses[kA]) && std::isinf(scene.masses[kC])) {
    return makeError(Reason::kTwoWalls, "masses",
                     "m_A and m_C are both inf; at most one of A and C may be a wall");
  }
  return std::nullopt;
}

std::optional<ValidationError> checkFiniteAndOrdered(const ThreeBodyScene& scene) {
  for (const auto& [values, name, symbol, unit] :
       {std::tuple{&scene.positions, "positions", "x_", "position must be a finite number in m"},
        std::tuple{&scene.velocities, "velocities", "v_", "velocity must be a finite number in m/s"}}) {
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite((*values)[i])) {
        return makeError(Reason::kNonFiniteValue, indexedField(name, i),
                         std::string(symbol) + kParticleNames[i] + " is " + formatValue((*values)[i]) + "; a " + unit);
      }
    }
  }
  const auto& x = scene.positions;
  for (int i = 0; i < 2; ++i) {
    if (x[i] == x[i + 1]) {
      return makeError(Reason::kPositionsCoincident, "positions",
                       std::string("x_") + kParticleNames[i] + " = x_" + kParticleNames[i + 1] + " = " +
                           formatValue(x[i]) + " m; " + kParticleNames[i] + " and " + kParticleNames[i + 1] +
                           " must start apart");
    }
  }
  if (!(x[kA] > x[kB] && x[kB] > x[kC])) {
    return makeError(Reason::kPositionsNotOrdered, "positions",
                     "x_A = " + formatValue(x[kA]) + " m, x_B = " + formatValue(x[kB]) + " m, x_C = " +
                         formatValue(x[kC]) + " m must be strictly decreasing: x_A > x_B > x_C");
  }
  return std::nullopt;
}

/// Everything the engine forms must be representable: momenta, energies in the wall's
/// frame, relative velocities and gaps.
std::optional<ValidationError> checkDoubleRange(const ThreeBodyScene& scene) {
  const int wall = scene.wallIndex();
  const double frame_velocity = wall >= 0 ? scene.velocities[wall] : 0.0;
  for (int i = 0; i < 3; ++i) {
    if (i == wall) continue;
    const double m = scene.masses[i];
    const double v = scene.velocities[i];
    const double relative = v - frame_velocity;
    if (!std::isfinite(relative) || !isFiniteProduct(m, v) || !isFiniteProduct(m * relative, relative) ||
        !isFiniteProduct(m, 4.0 * std::fabs(v) + 4.0 * std::fabs(frame_velocity))) {
      return makeError(Reason::kOverflow, indexedField("velocities", i),
                       "momentum or kinetic energy of " + std::string(kParticleNames[i]) + " (m = " +
                           formatValue(m) + " kg, v = " + formatValue(v) +
                           " m/s) overflows a double; rescale the units");
    }
  }
  const auto& x = scene.positions;
  for (int i = 0; i < 2; ++i) {
    if (!std::isfinite(x[i] - x[i + 1]) || !std::isfinite(scene.velocities[i] - scene.velocities[i + 1]) ||
        !std::isfinite(2.0 * (std::fabs(scene.velocities[i]) + std::fabs(scene.velocities[i + 1])))) {
      return makeError(Reason::kOverflow, "positions",
                       "the gap or relative velocity between " + std::string(kParticleNames[i]) + " and " +
                           kParticleNames[i + 1] + " overflows a double; rescale the units");
    }
  }
  return std::nullopt;
}

/// Every count is reported as a 64-bit integer, and no start of these masses can have more
/// collisions than ceil(pi / alpha). Only a light B makes that many: the count grows like
/// pi sqrt(m / m_B) with m the lighter of A and C.
std::optional<ValidationError> checkCountFits(const ThreeBodyScene& scene) {
  if (checkedMaxPossibleCollisionCount(scene.masses)) return std::nullopt;
  const double lighter_outer = std::min(scene.masses[kA], scene.masses[kC]);
  return makeError(Reason::kOverflow, "masses",
                   "these masses allow up to ceil(pi / alpha) = " + formatShort(M_PI / anglesFor(scene.masses).alpha) +
                       " collisions, more than 2^64 - 1 = 18446744073709551615, the largest count collision_lab "
                       "reports; the count grows like pi sqrt(m / m_B) with m = " + formatValue(lighter_outer) +
                       " kg the lighter of A and C: make B heavier or that body lighter");
}

/// The first contact certainly happens: its time and the positions then must be doubles.
/// (Later contacts beyond the range of a double are reported as inf.)
std::optional<ValidationError> checkFirstContact(const ThreeBodyScene& scene) {
  const std::optional<Pair> first = firstPair(scene);
  if (!first) return std::nullopt;
  const int pair_index = pairIndex(*first);
  const auto& x = scene.positions;
  const auto& v = scene.velocities;
  // Far inside the range in double (each value within 1e-15 relative of the exact one), the
  // exact check below cannot fail: skip its rationals, which cost as much as a short run.
  constexpr double kFarInside = 1e300;
  const double time_near = (x[pair_index] - x[pair_index + 1]) / (v[pair_index + 1] - v[pair_index]);
  bool far_inside = time_near <= kFarInside;
  for (int i = 0; i < 3; ++i) far_inside = far_inside && std::fabs(x[i]) <= kFarInside && std::fabs(v[i]) * time_near <= kFarInside;
  if (far_inside) return std::nullopt;
  using exact::Rational;
  const Rational time = (Rational(x[pair_index]) - Rational(x[pair_index + 1])) /
                        (Rational(v[pair_index + 1]) - Rational(v[pair_index]));
  const Rational largest(std::numeric_limits<double>::max());
  const auto text = [](const Rational& q) { return HighPrecision(HighPrecision(numerator(q)) / HighPrecision(denominator(q))).str(3); };
  const std::string contact = std::string("the first contact, of ") + kParticleNames[pair_index] + " and " +
                              kParticleNames[pair_index + 1] + ", ";
  if (time > largest) {
    return makeError(Reason::kOverflow, "positions",
                     contact + "would come at t = " + text(time) +
                         " s, beyond the largest double (1.8e+308); a longer unit of time brings it into range");
  }
  for (int i = 0; i < 3; ++i) {
    const Rational position = Rational(x[i]) + Rational(v[i]) * time;
    if (abs(position) > largest) {
      return makeError(Reason::kOverflow, "positions",
                       contact + "at t = " + text(time) + " s, would find " + kParticleNames[i] + " at " +
                           text(position) +
                           " m, beyond the largest double (1.8e+308); a longer unit of length brings it into range");
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<ValidationError> validate(const ThreeBodyScene& scene) {
  if (auto error = checkMasses(scene)) return error;
  if (auto error = checkFiniteAndOrdered(scene)) return error;
  if (auto error = checkDoubleRange(scene)) return error;
  if (auto error = checkCountFits(scene)) return error;
  const bool ab_approach = scene.velocities[kA] < scene.velocities[kB];
  const bool bc_approach = scene.velocities[kB] < scene.velocities[kC];
  if (ab_approach && bc_approach && exact::compareFirstContactTimes(scene) == 0) {
    return makeError(Reason::kTripleCollision, "positions",
                     "A, B and C would meet at the same instant (an exact triple collision), "
                     "which three-body elastic collisions do not define");
  }
  return checkFirstContact(scene);
}

std::optional<Pair> firstPair(const ThreeBodyScene& scene) {
  const auto& v = scene.velocities;
  const bool ab = v[kA] < v[kB];
  const bool bc = v[kB] < v[kC];
  if (ab && bc) return exact::compareFirstContactTimes(scene) < 0 ? Pair::AB : Pair::BC;
  if (ab) return Pair::AB;
  if (bc) return Pair::BC;
  return std::nullopt;
}

}  // namespace core
}  // namespace collision_lab
