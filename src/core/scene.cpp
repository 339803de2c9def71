#include "collision_lab/core/scene.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "collision_lab/core/exact.h"

namespace collision_lab {

namespace {

const char* const kParticleNames[3] = {"A", "B", "C"};

std::string indexedField(const char* vector_name, int i) {
  return std::string(vector_name) + "[" + std::to_string(i) + "]";
}

/// Shortest text that reads back as the same double.
std::string formatValue(double value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::string(buffer, end);
}

/// The message always starts with the field, so one line tells the user where to look.
ValidationError makeError(Reason reason, const std::string& field, const std::string& message) {
  return ValidationError{reason, field, field + ": " + message};
}

bool isFiniteProduct(double a, double b) { return std::isfinite(a * b); }

/// Collision counts are 64-bit; the count never exceeds ceil(pi / alpha).
constexpr double kMaxCollisionCount = 9.2e18;
/// Beyond this finite-mass ratio the 100-digit decisions of the engine lose their margin;
/// a body that much heavier is a wall to all digits that matter.
constexpr double kMaxMassRatio = 1e100;

}  // namespace

bool Scene::isWall(int i) const { return masses[i] == std::numeric_limits<double>::infinity(); }

int Scene::wallIndex() const {
  if (isWall(kA)) return kA;
  if (isWall(kC)) return kC;
  return -1;
}

const char* reasonName(Reason r) {
  switch (r) {
    case Reason::kOk: return "OK";
    case Reason::kNonFiniteValue: return "NON_FINITE_VALUE";
    case Reason::kNonPositiveMass: return "NON_POSITIVE_MASS";
    case Reason::kTwoWalls: return "TWO_WALLS";
    case Reason::kInfiniteMiddleMass: return "INFINITE_MIDDLE_MASS";
    case Reason::kPositionsNotOrdered: return "POSITIONS_NOT_ORDERED";
    case Reason::kPositionsCoincident: return "POSITIONS_COINCIDENT";
    case Reason::kTripleCollision: return "TRIPLE_COLLISION";
    case Reason::kOverflow: return "OVERFLOW";
  }
  return "UNKNOWN";
}

std::optional<ValidationError> validate(const Scene& scene) {
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
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(scene.positions[i])) {
      const std::string field = indexedField("positions", i);
      return makeError(Reason::kNonFiniteValue, field,
                       std::string("x_") + kParticleNames[i] + " is " + formatValue(scene.positions[i]) +
                           "; a position must be a finite number in m");
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(scene.velocities[i])) {
      const std::string field = indexedField("velocities", i);
      return makeError(Reason::kNonFiniteValue, field,
                       std::string("v_") + kParticleNames[i] + " is " + formatValue(scene.velocities[i]) +
                           "; a velocity must be a finite number in m/s");
    }
  }
  const auto& x = scene.positions;
  for (int i = 0; i < 2; ++i) {
    if (x[i] == x[i + 1]) {
      return makeError(Reason::kPositionsCoincident, "positions",
                       std::string("positions of ") + kParticleNames[i] + " and " + kParticleNames[i + 1] +
                           " coincide at " + formatValue(x[i]) + " m; they must be distinct");
    }
  }
  if (!(x[kA] > x[kB] && x[kB] > x[kC])) {
    return makeError(Reason::kPositionsNotOrdered, "positions",
                     "positions (" + formatValue(x[kA]) + ", " + formatValue(x[kB]) + ", " +
                         formatValue(x[kC]) + ") m must be strictly decreasing: x_A > x_B > x_C");
  }

  // Everything the engine forms must be representable: momenta, energies in the wall's
  // frame, relative velocities and gaps.
  const int wall = scene.wallIndex();
  const double frame_velocity = wall >= 0 ? scene.velocities[wall] : 0.0;
  for (int i = 0; i < 3; ++i) {
    if (i == wall) continue;
    const double m = scene.masses[i];
    const double v = scene.velocities[i];
    const double relative = v - frame_velocity;
    if (!std::isfinite(relative) || !isFiniteProduct(m, v) || !isFiniteProduct(m * relative, relative) ||
        !isFiniteProduct(m, 4.0 * std::fabs(v) + 4.0 * std::fabs(frame_velocity))) {
      const std::string field = indexedField("velocities", i);
      return makeError(Reason::kOverflow, field,
                       "momentum or kinetic energy of " + std::string(kParticleNames[i]) + " (m = " +
                           formatValue(m) + " kg, v = " + formatValue(v) +
                           " m/s) overflows a double; rescale the units");
    }
  }
  for (int i = 0; i < 2; ++i) {
    if (!std::isfinite(x[i] - x[i + 1]) || !std::isfinite(scene.velocities[i] - scene.velocities[i + 1]) ||
        !std::isfinite(2.0 * (std::fabs(scene.velocities[i]) + std::fabs(scene.velocities[i + 1])))) {
      return makeError(Reason::kOverflow, "positions",
                       "the gap or relative velocity between " + std::string(kParticleNames[i]) + " and " +
                           kParticleNames[i + 1] + " overflows a double; rescale the units");
    }
  }

  // The collision count is about pi / alpha; it must fit the 64-bit counters (mass
  // ratios up to ~1e36), and the mass ratios themselves must stay representable.
  double mass_min = std::numeric_limits<double>::infinity(), mass_max = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (scene.isWall(i)) continue;
    mass_min = std::min(mass_min, scene.masses[i]);
    mass_max = std::max(mass_max, scene.masses[i]);
  }
  const double b_over_a = scene.isWall(kA) ? 0.0 : scene.masses[kB] / scene.masses[kA];
  const double b_over_c = scene.isWall(kC) ? 0.0 : scene.masses[kB] / scene.masses[kC];
  const double alpha = std::atan(std::sqrt(b_over_a * (1 + b_over_c) + b_over_c));
  if (!(3.5 / alpha < kMaxCollisionCount)) {
    return makeError(Reason::kOverflow, "masses",
                     "the mass ratios (largest / smallest = " + formatValue(mass_max / mass_min) +
                         ") are too extreme: the collision count would not fit 2^63");
  }
  if (!(mass_max / mass_min <= kMaxMassRatio)) {
    return makeError(Reason::kOverflow, "masses",
                     "the ratio of the largest to the smallest finite mass exceeds 1e100 (" + formatValue(mass_max) +
                         " / " + formatValue(mass_min) + "); make the heavy body a wall (inf) instead");
  }

  const bool ab_approach = scene.velocities[kA] < scene.velocities[kB];
  const bool bc_approach = scene.velocities[kB] < scene.velocities[kC];
  if (ab_approach && bc_approach && exact::compareFirstContactTimes(scene) == 0) {
    return makeError(Reason::kTripleCollision, "positions",
                     "A, B and C would meet at the same instant (an exact triple collision), "
                     "which three-body elastic collisions do not define");
  }
  // The first contact must happen at a representable time and place.
  for (int left : {kA, kB}) {
    const double approach = scene.velocities[left + 1] - scene.velocities[left];
    if (!(approach > 0)) continue;
    const double time = (x[left] - x[left + 1]) / approach;
    bool representable = std::isfinite(time);
    for (int i = 0; i < 3 && representable; ++i) {
      representable = std::isfinite(x[i] + scene.velocities[i] * time);
    }
    if (!representable) {
      return makeError(Reason::kOverflow, "positions",
                       "the first contact would come at t = " + formatValue(time) +
                           " s or beyond the range of a double in position; rescale the units");
    }
  }
  return std::nullopt;
}

}  // namespace collision_lab
