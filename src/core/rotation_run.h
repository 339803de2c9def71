// Internal to collision_lab_core: the rotation model (three elastic bodies) as runScene
// uses it. Its prediction's values, and the run of such a scene: the event engine's, with
// the closed form's and the paper's values put beside every impact (ImpactRecord::model),
// its summary taken from the known count where no decision is needed (nbody/elastic_triple.h).
#pragma once

#include "collision_lab/core/nbody/models.h"
#include "collision_lab/core/scene_run.h"
#include "correct_rounding.h"

namespace collision_lab {
namespace core {

/// Fills the rotation model's values of a three-elastic-body scene: its exact count, final
/// velocities, angles, psi, first pair and the paper's printed values. Precondition:
/// validate(scene) passed and scene.size() == 3.
void fillRotationPrediction(const Scene& scene, Prediction& prediction);

/// The filter of the final velocities (issue 48): the velocities after `count` impacts
/// (`first` first, then alternating) walked in detail::Filtered arithmetic, each with a
/// rigorous bound on its distance from the exact value (a wall's exact). The impact rule in
/// the form v_i' = ((m_i - m_j) v_i + 2 m_j v_j) / (m_i + m_j), whose bound does not grow
/// with the mass ratio: a body's error moves by its partner's times 2 m_j / M.
std::array<detail::Filtered, 3> filteredVelocitiesAfter(const Scene& scene, Pair first, std::uint64_t count);

/// Simulates a scene whose prediction has the rotation model's values (hasRotationValues),
/// in full or summary mode, up to options.lab.max_collisions. The summary is the same with
/// events and without; events only watch.
SceneSimulation simulateRotationScene(const Scene& scene, const Prediction& prediction,
                                      const SceneRunOptions& options, const SceneVisitors& visitors);

}  // namespace core
}  // namespace collision_lab
