// Static shapes in ODE that a script, a path or a joint moves: a geom
// without a body until it first moves, then a kinematic body (OdeWorld::
// FollowStaticGeoms); and the force sensors that hang from such a shape
// (MountGeom, HeldApart). Internal to modules/dynamics/ode.
#include <vector>

#include "framework/scene.h"
#include "modules/dynamics/ode/ode_internal.h"
#include "modules/dynamics/ode/ode_world.h"
#include "modules/dynamics/scene_walk.h"

namespace swarmsim::ode {

using dynamics::ShapeAt;

void OdeWorld::FollowStaticGeoms(const Scene& scene) {
  // A static shape that a script, a path or a joint moved becomes a kinematic
  // body from where it was, followed like the others from then on: it sweeps
  // to its new pose over the step and pushes what it meets. A move longer
  // than a quarter of its size is a jump (a door toggled open, a path's
  // follower put at the path's start): it is put there, pushing out what it
  // lands on, not ramming what lies between. One that holds dynamic shapes
  // in the scene tree always jumps: the scene carries them with it already
  // (as box2d and planar do), friction would carry them a second time. The
  // force sensors hanging from it hold on to it.
  size_t kept = 0;
  for (const StaticGeom& g : static_geoms_) {
    if (scene.world_pose_at(g.slot) == g.X_WS) {
      static_geoms_[kept++] = g;
      continue;
    }
    dBodyID body = dBodyCreate(world_);
    dBodySetKinematic(body);
    SetBodyPose(body, g.X_WS);
    dGeomSetBody(g.geom, body);
    KinematicBody k{body, g.slot, g.X_WS, g.X_WS, {}, {}};
    k.jump = 0.25 * scene.shapes()[scene.row_at(g.slot)].BoundingRadius();
    std::vector<uint32_t> subtree;
    scene.CollectSubtree(g.slot, &subtree);
    for (uint32_t s : subtree) {
      const ShapeData* shape = ShapeAt(scene, s);
      if (shape != nullptr && shape->dynamic) k.jump = 0;
    }
    kinematic_.push_back(k);
    for (SimForceSensor& f : force_sensors_)
      if (f.mount == g.geom && f.joint != nullptr) {
        dJointAttach(f.joint, f.child_body, body);
        dJointSetFixed(f.joint);
      }
  }
  static_geoms_.resize(kept);
}

dGeomID OdeWorld::MountGeom(const Scene& scene, uint32_t sensor_slot) const {
  int32_t p = scene.parent_at(sensor_slot);
  while (p >= 0 && scene.type_at(static_cast<uint32_t>(p)) != ObjectType::kShape)
    p = scene.parent_at(static_cast<uint32_t>(p));
  if (p < 0) return nullptr;
  for (const StaticGeom& g : static_geoms_)
    if (g.slot == static_cast<uint32_t>(p)) return g.geom;
  return nullptr;
}

bool OdeWorld::HeldApart(dGeomID a, dBodyID ba, dGeomID b, dBodyID bb) const {
  if (ba != nullptr && bb != nullptr) return false;  // bodies: the joint connects them
  const dGeomID mount = ba == nullptr ? a : b;
  const dBodyID child = ba == nullptr ? bb : ba;
  for (const SimForceSensor& f : force_sensors_)
    if (f.mount == mount && f.child_body == child && f.joint != nullptr) return true;
  return false;
}

}  // namespace swarmsim::ode
