// Bullet (the double-precision build when CMake found bullet-float64), configured as
// elastically as it allows (shared/physics.md, last section), with per-pair restitution.
#include <cmath>
#include <memory>
#include <optional>

#include <btBulletDynamicsCommon.h>

#include "engines.h"

namespace collision_lab {
namespace bench {

namespace {

/// Per-body restitutions r whose products r_p r_{p+1} are the pairs' e (Bullet combines a
/// contact's restitution as the product of its two bodies'). On a line only neighbours
/// touch, so a chain solve gives every pair its own e: r_0 = sqrt(e_0), r_{p+1} = e_p / r_p
/// (each product is e_p to within one rounding); after a zero r the next r is free and the
/// chain restarts. Empty when no such r exists (a pair with e = 0 between two with e > 0).
std::optional<std::vector<double>> bodyRestitutions(const core::Scene& scene) {
  const std::size_t pairs = scene.pairCount();
  auto fresh = [&](std::size_t pair) { return pair < pairs ? std::sqrt(scene.restitutionOf(pair)) : 1.0; };
  std::vector<double> r(scene.size(), 1.0);
  if (pairs == 0) return r;
  r[0] = fresh(0);
  for (std::size_t p = 0; p < pairs; ++p) {
    const double e = scene.restitutionOf(p);
    if (r[p] != 0.0) {
      r[p + 1] = e / r[p];
    } else if (e == 0.0) {
      r[p + 1] = fresh(p + 1);
    } else {
      return std::nullopt;
    }
  }
  return r;
}

SteppedRun runBullet(const core::Scene& scene, const StepConfig& config) {
  SteppedRun run;
  const auto restitution = bodyRestitutions(scene);
  if (!restitution) {
    run.unsupported = "Bullet multiplies the bodies' restitutions: a pair with e = 0 between two with e > 0 cannot be set";
    return run;
  }
  btDefaultCollisionConfiguration collision_config;
  btCollisionDispatcher dispatcher(&collision_config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &collision_config);
  world.setGravity(btVector3(0, 0, 0));
  btContactSolverInfo& info = world.getSolverInfo();
  info.m_restitutionVelocityThreshold = 0;         // default 0.2 m/s: no bounce below it
  info.m_solverMode &= ~SOLVER_USE_WARMSTARTING;  // no impulse carried between steps
  info.m_splitImpulse = 1;                          // penetration fixed without adding velocity
  info.m_splitImpulsePenetrationThreshold = 1e30;   // ... at every depth
  // No split-impulse position correction either: with the default m_erp2 = 0.8 the
  // pushes out of each overlap add up, and positions stop converging near 0.1-0.2 m on
  // scenes with thousands of fast collisions.
  info.m_erp2 = 0;

  const std::size_t n = scene.size();
  btSphereShape sphere(kEngineRadius);
  std::vector<std::unique_ptr<btRigidBody>> bodies(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool wall = scene.isWall(i);
    const btScalar mass = wall ? 0 : scene.masses[i];  // mass 0 = static: a wall is a static sphere
    btVector3 inertia(0, 0, 0);
    if (!wall) sphere.calculateLocalInertia(mass, inertia);
    btRigidBody::btRigidBodyConstructionInfo body_info(mass, nullptr, &sphere, inertia);
    body_info.m_startWorldTransform.setIdentity();
    body_info.m_startWorldTransform.setOrigin(btVector3(scene.positions[i] + engineOffset(i, n), 0, 0));
    body_info.m_restitution = (*restitution)[i];
    body_info.m_friction = 0;
    body_info.m_rollingFriction = 0;
    body_info.m_linearDamping = 0;
    body_info.m_angularDamping = 0;
    bodies[i] = std::make_unique<btRigidBody>(body_info);
    btRigidBody& body = *bodies[i];
    body.setLinearFactor(btVector3(1, 0, 0));  // motion on the x axis only
    body.setAngularFactor(0);
    body.setActivationState(DISABLE_DEACTIVATION);
    if (!wall) body.setLinearVelocity(btVector3(scene.velocities[i], 0, 0));
    world.addRigidBody(&body);
  }

  run.positions.resize(n);
  run.velocities.resize(n);
  auto read = [&] {
    for (std::size_t i = 0; i < n; ++i) {
      run.positions[i] = bodies[i]->getWorldTransform().getOrigin().x() - engineOffset(i, n);
      run.velocities[i] = bodies[i]->getLinearVelocity().x();
    }
  };
  read();
  CollisionCounter counter(run.velocities);
  run.steps = stepCount(config);
  for (std::uint64_t step = 0; step < run.steps; ++step) {
    world.stepSimulation(config.dt, 0);  // maxSubSteps 0: exactly one internal step of dt
    read();
    counter.update(run.velocities);
  }
  run.collisions = counter.count();
  for (auto& body : bodies) world.removeRigidBody(body.get());
  return run;
}

}  // namespace

SteppedMethod bulletMethod() {
#ifdef BT_USE_DOUBLE_PRECISION
  const char* precision = "double-precision build (bullet-float64)";
#else
  const char* precision = "single-precision build";
#endif
  return {"bullet",
          std::string("Bullet 3.24, ") + precision +
              ", btDiscreteDynamicsWorld with btSequentialImpulseConstraintSolver and "
              "btDbvtBroadphase, gravity 0, stepSimulation(dt, 0) (one step of dt). Spheres "
              "of radius 0.01 m; a wall is a static sphere (mass 0). Restitution: Bullet "
              "uses the product of the two bodies' m_restitution, so body i gets r_i with "
              "r_0 = sqrt(e_0), r_{p+1} = e_p / r_p: every neighbouring pair's product is its "
              "e to within one rounding (elastic scenes: r = 1 everywhere; on a line only "
              "neighbours touch). Every body: friction 0, rolling friction 0, "
              "damping 0, setLinearFactor(1,0,0), setAngularFactor(0), DISABLE_DEACTIVATION. "
              "Solver: m_restitutionVelocityThreshold = 0 (default 0.2 m/s), warm starting "
              "off, m_splitImpulse = 1, m_splitImpulsePenetrationThreshold = 1e30, m_erp2 = 0 "
              "(no split-impulse position correction; with the default 0.8 the position error "
              "stops converging near 0.1-0.2 m on the 10^6:1 scenes); other solver settings "
              "default (10 iterations).",
          runBullet};
}

}  // namespace bench
}  // namespace collision_lab
