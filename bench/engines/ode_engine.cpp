// ODE (double precision in Debian's build), configured as elastically as it allows
// (shared/physics.md, last section).
#include <array>
#include <cmath>
#include <mutex>

#include <ode/ode.h>

#include "engines.h"

namespace collision_lab {
namespace bench {

namespace {

struct OdeWorld {
  dWorldID world;
  dJointGroupID contacts;
};

/// Contact joints for every touching geom pair: bounce 1 at any speed, rigid (no ERP,
/// no CFM softness), frictionless.
void nearCallback(void* data, dGeomID a, dGeomID b) {
  auto* w = static_cast<OdeWorld*>(data);
  dContact contact[4];
  const int n = dCollide(a, b, 4, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) {
    contact[i].surface.mode = dContactBounce | dContactSoftERP | dContactSoftCFM;
    contact[i].surface.mu = 0;
    contact[i].surface.bounce = 1;
    contact[i].surface.bounce_vel = 0;
    contact[i].surface.soft_erp = 0;
    contact[i].surface.soft_cfm = 0;
    dJointID joint = dJointCreateContact(w->world, w->contacts, &contact[i]);
    dJointAttach(joint, dGeomGetBody(a), dGeomGetBody(b));
  }
}

SteppedRun runOde(const core::ThreeBodyScene& scene, const StepConfig& config) {
  static std::once_flag init;
  std::call_once(init, [] { dInitODE2(0); });
  OdeWorld w{dWorldCreate(), dJointGroupCreate(0)};
  dWorldSetGravity(w.world, 0, 0, 0);
  dWorldSetAutoDisableFlag(w.world, 0);
  dSpaceID space = dSimpleSpaceCreate(nullptr);

  const double r = kEngineRadius;
  const double offset[3] = {2 * r, 0.0, -2 * r};
  std::array<dBodyID, 3> bodies{};
  for (int i = 0; i < 3; ++i) {
    if (std::isinf(scene.masses[i])) {
      // A wall is a plane touching B's surface exactly when x_B reaches the wall.
      if (i == core::kC) dCreatePlane(space, 1, 0, 0, scene.positions[i] - r);
      else dCreatePlane(space, -1, 0, 0, -(scene.positions[i] + r));
      continue;
    }
    bodies[i] = dBodyCreate(w.world);
    dMass mass;
    dMassSetSphereTotal(&mass, scene.masses[i], r);
    dBodySetMass(bodies[i], &mass);
    dBodySetPosition(bodies[i], scene.positions[i] + offset[i], 0, 0);
    dBodySetLinearVel(bodies[i], scene.velocities[i], 0, 0);
    dGeomID geom = dCreateSphere(space, r);
    dGeomSetBody(geom, bodies[i]);
  }

  SteppedRun run;
  auto read = [&] {
    for (int i = 0; i < 3; ++i) {
      if (!bodies[i]) {  // a static wall
        run.positions[i] = scene.positions[i];
        run.velocities[i] = 0;
        continue;
      }
      run.positions[i] = dBodyGetPosition(bodies[i])[0] - offset[i];
      run.velocities[i] = dBodyGetLinearVel(bodies[i])[0];
    }
  };
  read();
  CollisionCounter counter(run.velocities);
  run.steps = stepCount(config);
  for (std::uint64_t step = 0; step < run.steps; ++step) {
    dSpaceCollide(space, &w, nearCallback);
    dWorldStep(w.world, config.dt);
    dJointGroupEmpty(w.contacts);
    read();
    counter.update(run.velocities);
  }
  run.collisions = counter.count();
  dSpaceDestroy(space);  // destroys the geoms too (cleanup mode on by default)
  dJointGroupDestroy(w.contacts);
  dWorldDestroy(w.world);
  return run;
}

}  // namespace

SteppedMethod odeMethod() {
  return {"ode",
          "ODE 0.16 (double precision), dWorldStep (the direct solver), gravity 0, "
          "auto-disable off, dSimpleSpace. Spheres of radius 0.01 m (dMassSetSphereTotal "
          "with the scene's mass); a wall is a plane. Every contact: mode dContactBounce | "
          "dContactSoftERP | dContactSoftCFM, bounce 1, bounce_vel 0 (default: no bounce "
          "without dContactBounce), soft_erp 0, soft_cfm 0, mu 0; up to 4 contacts per "
          "pair. Motion stays on the x axis because every contact normal is +-x.",
          runOde};
}

}  // namespace bench
}  // namespace collision_lab
