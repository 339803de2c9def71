// Box2D 2.4 (float only; b2_linearSlop is compiled in), configured as elastically as it
// allows (shared/physics.md, last section).
#include <array>
#include <cmath>

#include <box2d/box2d.h>

#include "engines.h"

namespace collision_lab {
namespace bench {

namespace {

constexpr int kVelocityIterations = 8;
constexpr int kPositionIterations = 3;

SteppedRun runBox2d(const core::ThreeBodyScene& scene, const StepConfig& config) {
  b2World world(b2Vec2(0.0f, 0.0f));
  world.SetAllowSleeping(false);
  world.SetWarmStarting(false);
  world.SetContinuousPhysics(true);

  const double r = kEngineRadius;
  const double offset[3] = {2 * r, 0.0, -2 * r};
  std::array<b2Body*, 3> bodies{};
  for (int i = 0; i < 3; ++i) {
    const bool wall = std::isinf(scene.masses[i]);
    b2BodyDef body_def;
    body_def.type = wall ? b2_staticBody : b2_dynamicBody;
    body_def.position.Set(static_cast<float>(scene.positions[i] + offset[i]), 0.0f);
    body_def.linearVelocity.Set(wall ? 0.0f : static_cast<float>(scene.velocities[i]), 0.0f);
    body_def.fixedRotation = true;
    body_def.bullet = true;
    body_def.allowSleep = false;
    bodies[i] = world.CreateBody(&body_def);
    b2CircleShape circle;
    circle.m_radius = static_cast<float>(r);
    b2FixtureDef fixture;
    fixture.shape = &circle;
    fixture.density = wall ? 0.0f : static_cast<float>(scene.masses[i] / (M_PI * r * r));
    fixture.friction = 0.0f;
    fixture.restitution = 1.0f;
    fixture.restitutionThreshold = 0.0f;  // default 1 m/s: no bounce below it
    bodies[i]->CreateFixture(&fixture);
  }

  SteppedRun run;
  auto read = [&] {
    for (int i = 0; i < 3; ++i) {
      run.positions[i] = bodies[i]->GetPosition().x - offset[i];
      run.velocities[i] = bodies[i]->GetLinearVelocity().x;
    }
  };
  read();
  CollisionCounter counter(run.velocities);
  run.steps = stepCount(config);
  const float dt = static_cast<float>(config.dt);
  for (std::uint64_t step = 0; step < run.steps; ++step) {
    world.Step(dt, kVelocityIterations, kPositionIterations);
    read();
    counter.update(run.velocities);
  }
  run.collisions = counter.count();
  return run;
}

}  // namespace

SteppedMethod box2dMethod() {
  return {"box2d",
          "Box2D 2.4.1 (float only), gravity 0, sleeping off, warm starting off, continuous "
          "physics on, Step(dt, 8 velocity, 3 position iterations). Circles of radius "
          "0.01 m on y = 0 with density m / (pi r^2); a wall is a static circle. Every body: "
          "restitution 1 (pair: max), restitutionThreshold 0 (default 1 m/s; pair: min), "
          "friction 0, fixedRotation, bullet = true. Compiled in: b2_linearSlop = 0.005 m, "
          "b2_maxTranslation = 2 m per step (caps speed at 2/dt). Motion stays on y = 0 "
          "because every contact normal is +-x.",
          runBox2d};
}

}  // namespace bench
}  // namespace collision_lab
