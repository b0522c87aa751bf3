// Force sensors in ODE: a fixed joint with dJointSetFeedback per sensor.
#include <vector>

#include "framework/scene.h"
#include "modules/dynamics/ode/ode_internal.h"
#include "modules/dynamics/ode/ode_world.h"
#include "modules/dynamics/scene_walk.h"
#include "modules/force_sensor/force_sensor.h"

namespace swarmsim::ode {

void OdeWorld::BuildForceSensors(const Scene& scene, const std::vector<dBodyID>& body_of) {
  const Rows<ForceSensorData>& sensors = *force_sensor::RowsOf(scene);  // Build checked Any
  for (uint32_t row : dynamics::ForceSensorRowsInSlotOrder(scene)) {
    const uint32_t s = sensors.owners[row];
    if (sensors.rows[row].broken) continue;
    const int32_t child_slot = dynamics::FirstDynamicShapeBelow(scene, s);
    if (child_slot < 0) continue;  // nothing dynamic to hold: no reading
    const dBodyID child = body_of[child_slot];
    const dBodyID parent = dynamics::NearestBodyAbove<dBodyID>(scene, body_of, s, nullptr);
    SimForceSensor f{};
    f.mount = parent == nullptr ? MountGeom(scene, s) : nullptr;
    f.row = row;
    f.child_body = child;
    f.X_BS = BodyPose(child).Inverse() * scene.world_pose_at(s);
    feedback_.push_back(std::make_unique<dJointFeedback>());
    f.feedback = feedback_.back().get();
    f.joint = dJointCreateFixed(world_, nullptr);
    dJointAttach(f.joint, child, parent);
    dJointSetFixed(f.joint);
    dJointSetFeedback(f.joint, f.feedback);
    has_mounts_ = has_mounts_ || f.mount != nullptr;
    force_sensors_.push_back(f);
  }
}

void OdeWorld::ReadForceSensors(Scene* scene) {
  if (force_sensors_.empty()) return;
  Rows<ForceSensorData>& sensors = *force_sensor::RowsOf(scene);  // Build found some
  for (SimForceSensor& f : force_sensors_) {
    if (!f.joint) continue;
    // Feedback of the last substep: force and torque (about the child's
    // centre of mass) that the joint applies to the child, world frame.
    const Vec3 f_W{f.feedback->f1[0], f.feedback->f1[1], f.feedback->f1[2]};
    const Vec3 t_com_W{f.feedback->t1[0], f.feedback->t1[1], f.feedback->t1[2]};
    const Pose X_WB = BodyPose(f.child_body);
    const Pose X_WS = X_WB * f.X_BS;
    // About the sensor origin: t_S = t_com + (p_com - p_S) x f.
    const Vec3 t_W = t_com_W + (X_WB.p - X_WS.p).Cross(f_W);
    const Quat q_SW = X_WS.q.Conjugate();
    ForceSensorData& data = sensors.rows[f.row];
    if (RecordForceSensorSample(&data, q_SW.Rotate(f_W), q_SW.Rotate(t_W))) {
      dJointAttach(f.joint, nullptr, nullptr);
      dJointDestroy(f.joint);
      f.joint = nullptr;
    }
  }
}

}  // namespace swarmsim::ode
