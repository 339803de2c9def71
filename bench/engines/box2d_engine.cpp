// Box2D 2.4 (float only; b2_linearSlop is compiled in), configured as elastically as it
// allows (shared/physics.md, last section), with each contact's restitution set to its
// pair's e.
#include <algorithm>
#include <cmath>
#include <vector>

#include <box2d/box2d.h>

#include "engines.h"

namespace collision_lab {
namespace bench {

namespace {

constexpr int kVelocityIterations = 8;
constexpr int kPositionIterations = 3;

/// Sets every contact's restitution to its pair's e (Box2D would mix the fixtures' values
/// as their max, which cannot give each pair of a chain its own e) and its restitution
/// threshold to 0. Bodies carry their index as user data; bodies i and j touch as pair
/// min(i, j) (on a line only neighbours touch).
class PairRestitution : public b2ContactListener {
 public:
  explicit PairRestitution(const core::Scene& scene) : scene_(scene) {}
  void PreSolve(b2Contact* contact, const b2Manifold*) override {
    const auto a = contact->GetFixtureA()->GetBody()->GetUserData().pointer;
    const auto b = contact->GetFixtureB()->GetBody()->GetUserData().pointer;
    contact->SetRestitution(static_cast<float>(scene_.restitutionOf(std::min(a, b))));
    contact->SetRestitutionThreshold(0.0f);
  }

 private:
  const core::Scene& scene_;
};

SteppedRun runBox2d(const core::Scene& scene, const StepConfig& config) {
  b2World world(b2Vec2(0.0f, 0.0f));
  world.SetAllowSleeping(false);
  world.SetWarmStarting(false);
  world.SetContinuousPhysics(true);
  PairRestitution listener(scene);
  world.SetContactListener(&listener);

  const std::size_t n = scene.size();
  const double r = kEngineRadius;
  std::vector<b2Body*> bodies(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool wall = scene.isWall(i);
    b2BodyDef body_def;
    body_def.type = wall ? b2_staticBody : b2_dynamicBody;
    body_def.position.Set(static_cast<float>(scene.positions[i] + engineOffset(i, n)), 0.0f);
    body_def.linearVelocity.Set(wall ? 0.0f : static_cast<float>(scene.velocities[i]), 0.0f);
    body_def.fixedRotation = true;
    body_def.bullet = true;
    body_def.allowSleep = false;
    body_def.userData.pointer = i;
    bodies[i] = world.CreateBody(&body_def);
    b2CircleShape circle;
    circle.m_radius = static_cast<float>(r);
    b2FixtureDef fixture;
    fixture.shape = &circle;
    fixture.density = wall ? 0.0f : static_cast<float>(scene.masses[i] / (M_PI * r * r));
    fixture.friction = 0.0f;
    fixture.restitution = 1.0f;           // replaced per contact by the pair's e (PreSolve)
    fixture.restitutionThreshold = 0.0f;  // default 1 m/s: no bounce below it
    bodies[i]->CreateFixture(&fixture);
  }

  SteppedRun run;
  run.positions.resize(n);
  run.velocities.resize(n);
  auto read = [&] {
    for (std::size_t i = 0; i < n; ++i) {
      run.positions[i] = bodies[i]->GetPosition().x - engineOffset(i, n);
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
          "0.01 m on y = 0 with density m / (pi r^2); a wall is a static circle. Every "
          "contact: restitution = the pair's e rounded to float, and restitution threshold 0 "
          "(default 1 m/s), both set in a b2ContactListener::PreSolve (the fixtures' own "
          "restitutions would mix as their max, which cannot give each pair of a chain its "
          "own e); each body carries its index, bodies i and i+1 are pair i. Every body: "
          "friction 0, fixedRotation, bullet = true. Compiled in: b2_linearSlop = 0.005 m, "
          "b2_maxTranslation = 2 m per step (caps speed at 2/dt). Motion stays on y = 0 "
          "because every contact normal is +-x.",
          runBox2d};
}

}  // namespace bench
}  // namespace collision_lab
