// Exact N-body reference for the tests: cpp_rational positions and velocities, advanced
// event by event with a plain O(N) scan for the next contact. Written from physics.md
// independently of the engine (no shared code, a different state: positions at the
// current time instead of line intercepts, the centre-of-mass form of the impact rule), each
// impact's e chosen by the scene's restitution model as physics.md states it.
// Bodies stuck by e = 0 are hit as one body of their total mass (engine.h, the cluster
// rule). An inelastic collapse is not resolved: the reference steps through its impacts
// until the cap, and its impact times approach the collapse time.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <boost/multiprecision/cpp_int.hpp>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {
namespace reference {

using Rational = boost::multiprecision::cpp_rational;

/// A scene of the tests: bodies listed right to left, one restitution e for every pair.
inline Scene makeScene(std::vector<double> masses, std::vector<double> positions, std::vector<double> velocities,
                       double e) {
  Scene s;
  s.masses = std::move(masses);
  s.positions = std::move(positions);
  s.velocities = std::move(velocities);
  s.restitution = {e};
  return s;
}

struct Event {
  std::size_t pair = 0;
  Rational time;      ///< [s]
  Rational position;  ///< contact point [m]
  Rational lost;      ///< kinetic energy lost [J]
  Rational before_right, before_left;  ///< velocities of bodies pair and pair + 1 before [m/s]
  Rational after_right, after_left;    ///< and after [m/s]
};

struct Run {
  std::vector<Event> events;
  bool truncated = false;                     ///< stopped at the cap with an impact due
  std::optional<std::size_t> multiple_first;  ///< a multiple collision of bodies first..first+2
  Rational multiple_time;                     ///< [s]
  std::vector<Rational> velocities;           ///< at the end [m/s]
  std::vector<Rational> positions;            ///< at the time of the last impact [m]
  Rational last_time;                         ///< of the last impact [s] (0 without any)
  Rational energy_lost;                       ///< [J]
};

/// Events in the order exact time, then pair index; a tie of two pairs sharing a body, or
/// a pair that approaches at zero gap right after an impact next to it, is a multiple
/// collision: the run ends before it. Precondition: validate(scene) passed.
Run simulate(const Scene& scene, std::uint64_t max_impacts);

/// An impact of a ring, with the velocities the pair's two bodies leave with.
struct RingEvent {
  std::size_t pair = 0;  ///< contact pair: body pair and body (pair + 1) mod N
  Rational time;         ///< [s]
  Rational after_right, after_left;  ///< of body pair and of its left body [m/s]
};

/// A ring (scene.ring = L > 0, every e > 0, no walls) walked event by event in rationals:
/// contact pair N-1 joins body N-1 and body 0 seen at x_0 - L. Written without the cluster
/// rule (a ring has no e = 0) and with positions never wrapped, so the seam is just the
/// offset L in one gap. Stops at the cap, when no pair approaches, or before a tie of two
/// pairs (which `multiple` then says).
struct RingRun {
  std::vector<RingEvent> events;
  bool multiple = false;
  std::vector<Rational> velocities;  ///< at the end [m/s]
};
RingRun simulateRing(const Scene& scene, std::uint64_t max_impacts);

/// The collapse time [s] of a run that its cap ended inside an inelastic collapse: Aitken's
/// limit, in rationals, of every `period`-th exact impact time (the same step of a repeating
/// pattern: every second for three bodies), which converge geometrically (docs/physics.md,
/// "Where the test constants come from").
double limitOfImpactTimes(const Run& run, std::size_t period = 2);

/// The collapse time [s] of `scene`, which collapses: the limit of its first `impacts`
/// exact impact times (80 settle the scenes of physics.md to 1e-13 s).
double collapseTime(const Scene& scene, std::uint64_t impacts = 80);

/// The impact count of three bodies (an outer one may be a wall; every e > 0), walked in
/// exact integers: after the first impact the two pairs alternate (physics.md), so the count
/// is decided by the approach speeds a = v_B - v_A, c = v_C - v_B alone. Impact AB maps
/// (a, c) to (-e_AB a, c + (1 + e_AB) m_A/(m_A + m_B) a) (the centre-of-mass rule of
/// physics.md, with m_A/(m_A + m_B) = 1 for a wall), BC likewise. The state is scaled by the
/// maps' common denominators at each impact (signs are all that matter) and by common powers
/// of two removed, so nothing is ever divided or normalised: linear cost per impact, for walks
/// far longer than simulate() can take (32,774 impacts of 1.8 million bits in seconds).
struct AlternationWalk {
  std::uint64_t count = 0;
  bool capped = false;  ///< the cap came first: a pair still approached
};
AlternationWalk alternationCount(const Scene& scene, std::uint64_t cap);

/// sqrt(sum m (v - reference)^2) / sqrt(sum m v0^2) over the finite bodies, in the frame of
/// the walls (the lab frame without walls): the scale-free energy norm.
double energyNormError(const Scene& scene, const std::vector<double>& velocities,
                       const std::vector<Rational>& reference);

}  // namespace reference
}  // namespace core
}  // namespace collision_lab
