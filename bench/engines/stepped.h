// Time-stepping methods compared against the exact event simulation: a hand-written
// fixed-step loop and real physics engines. Each runs an N-body scene (walls, per-pair
// restitution) from t = 0 to end_time in steps of dt and reports the state at end_time, so
// trajectories can be compared with the exact one at the same instant.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace bench {

struct SteppedRun {
  std::vector<double> positions;   ///< point-mass positions at end_time [m]
  std::vector<double> velocities;  ///< at end_time [m/s]
  std::uint64_t collisions = 0;    ///< counted as by CollisionCounter
  std::uint64_t steps = 0;
  /// Non-empty when the method cannot represent the scene: why (then nothing was run).
  std::string unsupported;
};

struct StepConfig {
  double dt = 1e-3;        ///< [s]
  double end_time = 1.0;   ///< [s]; the run takes round(end_time / dt) steps
};

/// Counts collisions of any stepping method the same way: pair p's collision is counted
/// when, from one step to the next, it goes from approaching (v_{p+1} > v_p) to not
/// approaching. Free flight never changes that state, so each count is one impact (or one
/// engine-side resolution of several impacts in one step).
class CollisionCounter {
 public:
  explicit CollisionCounter(const std::vector<double>& v) : approaching_(v.size() > 0 ? v.size() - 1 : 0) {
    update(v);  // sets the flags; nothing was approaching before, so nothing is counted
  }
  void update(const std::vector<double>& v) {
    for (std::size_t p = 0; p < approaching_.size(); ++p) {
      const bool now = v[p + 1] > v[p];
      count_ += approaching_[p] && !now;
      approaching_[p] = now;
    }
  }
  std::uint64_t count() const { return count_; }

 private:
  std::vector<char> approaching_;
  std::uint64_t count_ = 0;
};

/// One time-stepping method: a name for the CSV, the settings written into the report,
/// and the run itself. Walls are static (v = 0) in every engine scene.
struct SteppedMethod {
  std::string name;
  std::string settings;  ///< every setting, as prose for docs/speed_vs_error.md
  /// Precondition: validate(scene) passed and every wall is at rest.
  std::function<SteppedRun(const core::Scene&, const StepConfig&)> run;
};

/// Radius of the spheres/circles the engines use [m].
constexpr double kEngineRadius = 0.01;

/// Shift of body i's centre in an engine scene of n bodies [m]: neighbours differ by 2r, so
/// spheres touch exactly when the point masses would (A +2r, B 0, C -2r for three bodies).
inline double engineOffset(std::size_t body, std::size_t n) {
  return kEngineRadius * (static_cast<double>(n) - 1.0 - 2.0 * static_cast<double>(body));
}

/// Number of steps for a config (round(end_time / dt)).
std::uint64_t stepCount(const StepConfig& config);

/// The hand-written fixed-step loop, then every real engine this build found.
std::vector<SteppedMethod> steppedMethods();

}  // namespace bench
}  // namespace collision_lab
