// Two bodies at any mass ratio (1e-300 against 1e300): accepted, predicted in closed form and
// correctly rounded, simulated by the engine; against the exact rational reference.
#include <gtest/gtest.h>

#include <vector>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/models.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

struct TwoBodyCase {
  const char* name;
  Scene scene;
};

std::vector<TwoBodyCase> extremeRatioScenes() {
  using reference::makeScene;
  return {{"both moving, e = 1", makeScene({1e-300, 1e300}, {1, 0}, {-1, 1}, 1.0)},
          {"heavy at rest, e = 1", makeScene({1e-300, 1e300}, {1, 0}, {-1, 0}, 1.0)},
          {"both moving, e = 0.5", makeScene({1e300, 1e-300}, {1, 0}, {-1, 1}, 0.5)},
          {"heavy at rest, e = 0.5", makeScene({1e300, 1e-300}, {1, 0}, {0, 1}, 0.5)}};
}

TEST(TwoBodyAnyRatio, AcceptedAndPredictedCorrectlyRounded) {
  for (const TwoBodyCase& c : extremeRatioScenes()) {
    ASSERT_FALSE(validate(c.scene)) << c.name << ": " << validate(c.scene)->message;
    ASSERT_EQ(chooseModel(c.scene).kind, ModelKind::kTwoBody) << c.name;
    const Prediction p = *predict(c.scene);
    const reference::Run run = reference::simulate(c.scene, 10);
    ASSERT_EQ(run.events.size(), 1u) << c.name;
    EXPECT_EQ(p.impact_count, std::uint64_t{1}) << c.name;
    EXPECT_EQ(*p.impact_time, static_cast<double>(run.events[0].time)) << c.name;
    EXPECT_EQ(*p.impact_position, static_cast<double>(run.events[0].position)) << c.name;
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(p.final_velocities[i], static_cast<double>(run.velocities[i])) << c.name << ", body " << i;
    }
    EXPECT_EQ(p.energy_lost, static_cast<double>(run.energy_lost)) << c.name;
    if (c.scene.restitution[0] < 1.0) EXPECT_GT(p.energy_lost, 0.0) << c.name;  // mu (1 - e^2) dv^2 / 2 ~ 1e-300 J
  }
}

TEST(TwoBodyAnyRatio, EngineSimulatesTheSameImpact) {
  for (const TwoBodyCase& c : extremeRatioScenes()) {
    const SceneSimulation run = runEngine(c.scene, EngineOptions{});
    ASSERT_EQ(run.stop, StopReason::kFinished) << c.name << ": " << run.stop_message;
    const reference::Run exact = reference::simulate(c.scene, 10);
    EXPECT_EQ(run.impact_count, 1u) << c.name;
    EXPECT_EQ(run.final_time, static_cast<double>(exact.last_time)) << c.name;
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(run.final_velocities[i], static_cast<double>(exact.velocities[i])) << c.name << ", body " << i;
    }
    // The heat mu (1 - e^2) dv^2 / 2 with mu ~ the light mass, not lost to m_heavy / m_light = inf.
    EXPECT_NEAR(run.energy_lost, static_cast<double>(exact.energy_lost), 1e-15 * static_cast<double>(exact.energy_lost))
        << c.name;
  }
}

TEST(TwoBodyAnyRatio, ThreeBodiesKeepTheRatioLimit) {
  const Scene three = reference::makeScene({1e-300, 1, 1e300}, {2, 1, 0}, {-1, 0, 1}, 0.5);
  const auto error = validate(three);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->reason, Reason::kOverflow);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
