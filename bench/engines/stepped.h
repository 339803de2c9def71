// Time-stepping methods compared against the exact event simulation: a hand-written
// fixed-step loop and real physics engines. Each runs a scene from t = 0 to end_time in
// steps of dt and reports the state at end_time, so trajectories can be compared with
// the exact one at the same instant.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace bench {

struct SteppedRun {
  std::array<double, 3> positions{};   ///< point-mass positions at end_time [m]
  std::array<double, 3> velocities{};  ///< at end_time [m/s]
  std::uint64_t collisions = 0;        ///< counted as by CollisionCounter
  std::uint64_t steps = 0;
};

struct StepConfig {
  double dt = 1e-3;        ///< [s]
  double end_time = 1.0;   ///< [s]; the run takes round(end_time / dt) steps
};

/// Counts collisions of any stepping method the same way: a pair's collision is counted
/// when, from one step to the next, it goes from approaching (v_right > v_left, e.g.
/// v_B > v_A for AB) to not approaching. Free flight never changes that state, so each
/// count is one impact (or one engine-side resolution of several impacts in one step).
class CollisionCounter {
 public:
  explicit CollisionCounter(const std::array<double, 3>& v) { update(v); }
  void update(const std::array<double, 3>& v) {
    const bool ab = v[core::kB] > v[core::kA];
    const bool bc = v[core::kC] > v[core::kB];
    count_ += (approach_ab_ && !ab) + (approach_bc_ && !bc);
    approach_ab_ = ab;
    approach_bc_ = bc;
  }
  std::uint64_t count() const { return count_; }

 private:
  bool approach_ab_ = false;
  bool approach_bc_ = false;
  std::uint64_t count_ = 0;
};

/// One time-stepping method: a name for the CSV, the settings written into the report,
/// and the run itself. Walls are static (v = 0) in every engine scene.
struct SteppedMethod {
  std::string name;
  std::string settings;  ///< every setting, as prose for docs/speed_vs_error.md
  std::function<SteppedRun(const core::ThreeBodyScene&, const StepConfig&)> run;
};

/// Radius of the spheres/circles the engines use [m]. Centres are shifted by the radii
/// (A by +2r, C by -2r) so spheres touch exactly when the point masses would.
constexpr double kEngineRadius = 0.01;

/// Number of steps for a config (round(end_time / dt)).
std::uint64_t stepCount(const StepConfig& config);

/// The hand-written fixed-step loop, then every real engine this build found.
std::vector<SteppedMethod> steppedMethods();

}  // namespace bench
}  // namespace collision_lab
