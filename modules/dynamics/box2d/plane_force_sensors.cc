// Force sensors in the plane: a weld joint per sensor, read through its
// reaction force and torque (in-plane force, torque about z).
#include <box2d/b2_weld_joint.h>

#include <vector>

#include "framework/scene.h"
#include "modules/dynamics/box2d/plane_world.h"
#include "modules/dynamics/scene_walk.h"
#include "modules/force_sensor/force_sensor.h"

namespace swarmsim::box2d {

void PlaneWorld::BuildForceSensors(const Scene& scene, const std::vector<int32_t>& body_of) {
  const Rows<ForceSensorData>& sensors = *force_sensor::RowsOf(scene);  // Build checked Any
  for (uint32_t row : dynamics::ForceSensorRowsInSlotOrder(scene)) {
    const uint32_t s = sensors.owners[row];
    if (sensors.rows[row].broken) continue;
    const int32_t child_slot = dynamics::FirstDynamicShapeBelow(scene, s);
    if (child_slot < 0) continue;  // nothing dynamic to hold: no reading
    const int32_t child = body_of[child_slot];
    const int32_t above = dynamics::NearestBodyAbove(scene, body_of, s, -1);
    b2Body* parent = above >= 0 ? bodies_[above].body : ground_;
    const Vec3& p_WS = scene.world_pose_at(s).p;
    b2WeldJointDef def;
    def.Initialize(
        parent, bodies_[child].body,
        b2Vec2(static_cast<float>(p_WS.x * scale_), static_cast<float>(p_WS.y * scale_)));
    force_sensors_.push_back({world_->CreateJoint(&def), row, s});
  }
}

void PlaneWorld::ReadForceSensors(Scene* scene) {
  if (!(last_dt_ > 0)) return;
  const float inv_dt = static_cast<float>(1.0 / last_dt_);
  const double inv_L = 1.0 / scale_;
  Rows<ForceSensorData>& sensors = *force_sensor::RowsOf(scene);  // Build found some
  for (PlaneForceSensor& f : force_sensors_) {
    if (!f.weld) continue;
    // Reaction on body B (the child) at the anchor, Box2D units -> N, N m.
    const b2Vec2 force = f.weld->GetReactionForce(inv_dt);
    const double torque = f.weld->GetReactionTorque(inv_dt);
    const Vec3 f_W{force.x * inv_L, force.y * inv_L, 0};
    const Vec3 t_W{0, 0, torque * inv_L * inv_L};
    // The sensor's frame: the child body's yaw carries it (its scene pose is
    // refreshed only after the physics phase).
    const Quat q_SW = scene->world_pose_at(f.slot).q.Conjugate();
    ForceSensorData& data = sensors.rows[f.row];
    if (RecordForceSensorSample(&data, q_SW.Rotate(f_W), q_SW.Rotate(t_W))) {
      world_->DestroyJoint(f.weld);
      f.weld = nullptr;
    }
  }
}

}  // namespace swarmsim::box2d
