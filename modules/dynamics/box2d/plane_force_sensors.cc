// Force sensors in the plane: a weld joint per sensor, read through its
// reaction force and torque (in-plane force, torque about z).
#include <box2d/b2_weld_joint.h>

#include <algorithm>
#include <vector>

#include "framework/force_sensor.h"
#include "framework/scene.h"
#include "modules/dynamics/box2d/plane_world.h"

namespace swarmsim::box2d {

void PlaneWorld::BuildForceSensors(const Scene& scene, const std::vector<int32_t>& body_of) {
  const auto owners = scene.force_sensor_owners();
  std::vector<uint32_t> rows(owners.size());
  for (uint32_t r = 0; r < rows.size(); ++r) rows[r] = r;
  std::sort(rows.begin(), rows.end(),
            [&](uint32_t a, uint32_t b) { return owners[a] < owners[b]; });
  for (uint32_t row : rows) {
    const uint32_t s = owners[row];
    if (scene.force_sensors()[row].broken) continue;
    // Child: the first dynamic shape below, not across a joint or another sensor.
    int32_t child = -1;
    std::vector<uint32_t> stack;
    std::vector<ObjectId> kids = scene.children(scene.IdAt(s));
    for (auto it = kids.rbegin(); it != kids.rend(); ++it) stack.push_back(it->index());
    while (!stack.empty() && child < 0) {
      const uint32_t c = stack.back();
      stack.pop_back();
      const ObjectType type = scene.type_at(c);
      if (type == ObjectType::kJoint || type == ObjectType::kForceSensor) continue;
      if (body_of[c] >= 0) {
        child = body_of[c];
        break;
      }
      std::vector<ObjectId> grand = scene.children(scene.IdAt(c));
      for (auto it = grand.rbegin(); it != grand.rend(); ++it) stack.push_back(it->index());
    }
    if (child < 0) continue;
    b2Body* parent = ground_;
    for (int32_t p = scene.parent_at(s); p >= 0; p = scene.parent_at(static_cast<uint32_t>(p)))
      if (body_of[p] >= 0) {
        parent = bodies_[body_of[p]].body;
        break;
      }
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
    ForceSensorData& data = scene->force_sensors()[f.row];
    if (RecordForceSensorSample(&data, q_SW.Rotate(f_W), q_SW.Rotate(t_W))) {
      world_->DestroyJoint(f.weld);
      f.weld = nullptr;
    }
  }
}

}  // namespace swarmsim::box2d
