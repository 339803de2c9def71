// ODE (double precision in Debian's build), configured as elastically as it allows
// (shared/physics.md, last section), with each contact's bounce set to its pair's e.
#include <cmath>
#include <mutex>
#include <vector>

#include <ode/ode.h>

#include "engines.h"

namespace collision_lab {
namespace bench {

namespace {

struct OdeWorld {
  dWorldID world;
  dJointGroupID contacts;
  const core::Scene* scene;
  std::vector<std::size_t> indices;  ///< body index of each geom (the geom's data points here)
};

std::size_t bodyIndex(dGeomID geom) { return *static_cast<const std::size_t*>(dGeomGetData(geom)); }

/// Contact joints for every touching geom pair: bounce = the pair's e at any speed, rigid
/// (no ERP, no CFM softness), frictionless. Bodies i and j touch as pair min(i, j) (on a
/// line only neighbours touch).
void nearCallback(void* data, dGeomID a, dGeomID b) {
  auto* w = static_cast<OdeWorld*>(data);
  dContact contact[4];
  const int n = dCollide(a, b, 4, &contact[0].geom, sizeof(dContact));
  const double e = w->scene->restitutionOf(std::min(bodyIndex(a), bodyIndex(b)));
  for (int i = 0; i < n; ++i) {
    contact[i].surface.mode = dContactBounce | dContactSoftERP | dContactSoftCFM;
    contact[i].surface.mu = 0;
    contact[i].surface.bounce = e;
    contact[i].surface.bounce_vel = 0;
    contact[i].surface.soft_erp = 0;
    contact[i].surface.soft_cfm = 0;
    dJointID joint = dJointCreateContact(w->world, w->contacts, &contact[i]);
    dJointAttach(joint, dGeomGetBody(a), dGeomGetBody(b));
  }
}

SteppedRun runOde(const core::Scene& scene, const StepConfig& config) {
  static std::once_flag init;
  std::call_once(init, [] { dInitODE2(0); });
  const std::size_t n = scene.size();
  OdeWorld w{dWorldCreate(), dJointGroupCreate(0), &scene, std::vector<std::size_t>(n)};
  dWorldSetGravity(w.world, 0, 0, 0);
  dWorldSetAutoDisableFlag(w.world, 0);
  dSpaceID space = dSimpleSpaceCreate(nullptr);

  const double r = kEngineRadius;
  std::vector<dBodyID> bodies(n, nullptr);
  for (std::size_t i = 0; i < n; ++i) {
    w.indices[i] = i;
    const double centre = scene.positions[i] + engineOffset(i, n);
    dGeomID geom;
    if (scene.isWall(i)) {
      // A wall is a plane where its sphere's inner surface would be: its neighbour touches
      // it exactly when the point masses meet.
      geom = i == 0 ? dCreatePlane(space, -1, 0, 0, -(centre - r)) : dCreatePlane(space, 1, 0, 0, centre + r);
    } else {
      bodies[i] = dBodyCreate(w.world);
      dMass mass;
      dMassSetSphereTotal(&mass, scene.masses[i], r);
      dBodySetMass(bodies[i], &mass);
      dBodySetPosition(bodies[i], centre, 0, 0);
      dBodySetLinearVel(bodies[i], scene.velocities[i], 0, 0);
      geom = dCreateSphere(space, r);
      dGeomSetBody(geom, bodies[i]);
    }
    dGeomSetData(geom, &w.indices[i]);
  }

  SteppedRun run;
  run.positions.resize(n);
  run.velocities.resize(n);
  auto read = [&] {
    for (std::size_t i = 0; i < n; ++i) {
      if (!bodies[i]) {  // a static wall
        run.positions[i] = scene.positions[i];
        run.velocities[i] = 0;
        continue;
      }
      run.positions[i] = dBodyGetPosition(bodies[i])[0] - engineOffset(i, n);
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
          "dContactSoftERP | dContactSoftCFM, bounce = the pair's e (each geom carries its "
          "body index; bodies i and i+1 are pair i), bounce_vel 0 (default: no bounce "
          "without dContactBounce), soft_erp 0, soft_cfm 0, mu 0; up to 4 contacts per "
          "pair. Motion stays on the x axis because every contact normal is +-x.",
          runOde};
}

}  // namespace bench
}  // namespace collision_lab
