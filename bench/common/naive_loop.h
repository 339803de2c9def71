// A naive event loop in one fixed precision: no error bounds, no escalation. Every
// decision (which pair is first, does a pair still approach) is a plain comparison in
// Scalar. It is the "lean loop" baseline of the speed benchmark and the "double-only"
// (or long-double-only, 50-digit-only) column of the hard-case table, where it shows
// what the core's adaptive decisions buy.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace bench {

template <class Scalar>
struct NaiveRun {
  std::uint64_t collision_count = 0;
  bool truncated = false;
  std::optional<core::Pair> first_pair;
  std::array<Scalar, 3> velocities{};  ///< after the last collision [m/s]
  std::array<Scalar, 3> positions{};   ///< at `time` (only with position tracking) [m]
  Scalar time = 0;                     ///< of the last collision (only with tracking) [s]
};

/// m_i / (m_i + m_j) in Scalar; 1 when i is a wall, 0 when j is.
template <class Scalar>
Scalar naiveMassFraction(double m_i, double m_j) {
  if (std::isinf(m_i)) return Scalar(1);
  if (std::isinf(m_j)) return Scalar(0);
  return Scalar(m_i) / (Scalar(m_i) + Scalar(m_j));
}

/// How a naive loop writes the elastic impulse. Both are exact in real arithmetic; they
/// round differently, so a zero approach speed can come out as +1e-17 in one and as 0 or
/// -1e-17 in the other, and which hard cases a fixed-precision loop gets wrong depends on it.
enum class ImpulseForm {
  kMassFraction,  ///< v_l += 2 m_r/(m_l+m_r) (v_r - v_l); v_r -= 2 m_l/(m_l+m_r) (v_r - v_l)
  kCentreOfMass,  ///< v_cm = (m_l v_l + m_r v_r)/(m_l+m_r); v' = 2 v_cm - v (walls: v_cm = v_wall)
};

/// Runs a validated scene to its end or to max_collisions. With kTrackPositions the loop
/// also advances time and all three positions to every contact (the "lean exact event
/// loop": times, positions, velocities, nothing stored); without it only velocities
/// change after the first pair is chosen.
template <class Scalar, bool kTrackPositions, ImpulseForm kForm = ImpulseForm::kMassFraction>
NaiveRun<Scalar> naiveEventLoop(const core::Scene& scene, std::uint64_t max_collisions) {
  NaiveRun<Scalar> run;
  const auto& m = scene.masses;
  // Per pair: fraction of the left body (A of AB, B of BC) and of the right body.
  const Scalar f_ab_a = naiveMassFraction<Scalar>(m[core::kA], m[core::kB]);
  const Scalar f_ab_b = naiveMassFraction<Scalar>(m[core::kB], m[core::kA]);
  const Scalar f_bc_b = naiveMassFraction<Scalar>(m[core::kB], m[core::kC]);
  const Scalar f_bc_c = naiveMassFraction<Scalar>(m[core::kC], m[core::kB]);
  auto& v = run.velocities;
  auto& x = run.positions;
  for (int i = 0; i < 3; ++i) {
    v[i] = Scalar(scene.velocities[i]);
    x[i] = Scalar(scene.positions[i]);
  }
  const bool ab = v[core::kB] - v[core::kA] > 0;
  const bool bc = v[core::kC] - v[core::kB] > 0;
  if (ab && bc) {
    const Scalar t_ab = (x[core::kA] - x[core::kB]) / (v[core::kB] - v[core::kA]);
    const Scalar t_bc = (x[core::kB] - x[core::kC]) / (v[core::kC] - v[core::kB]);
    run.first_pair = t_ab <= t_bc ? core::Pair::AB : core::Pair::BC;
  } else if (ab) {
    run.first_pair = core::Pair::AB;
  } else if (bc) {
    run.first_pair = core::Pair::BC;
  } else {
    return run;
  }
  bool is_ab = *run.first_pair == core::Pair::AB;
  std::uint64_t count = 0;
  for (;;) {
    const int left = is_ab ? core::kA : core::kB;
    const int right = left + 1;
    const Scalar approach = v[right] - v[left];
    if (!(approach > 0)) break;
    if (count == max_collisions) {
      run.truncated = true;
      break;
    }
    if constexpr (kTrackPositions) {
      const Scalar dt = (x[left] - x[right]) / approach;
      run.time += dt;
      x[core::kA] += v[core::kA] * dt;
      x[core::kB] += v[core::kB] * dt;
      x[core::kC] += v[core::kC] * dt;
    }
    const Scalar f_left = is_ab ? f_ab_a : f_bc_b;
    const Scalar f_right = is_ab ? f_ab_b : f_bc_c;
    if constexpr (kForm == ImpulseForm::kMassFraction) {
      v[left] += 2 * f_right * approach;
      v[right] -= 2 * f_left * approach;
    } else {
      const Scalar v_cm = f_left * v[left] + f_right * v[right];
      v[left] = 2 * v_cm - v[left];
      v[right] = 2 * v_cm - v[right];
    }
    ++count;
    is_ab = !is_ab;
  }
  run.collision_count = count;
  return run;
}

}  // namespace bench
}  // namespace collision_lab
