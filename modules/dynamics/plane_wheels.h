// What the planar engines (box2d, planar) call a wheel, and where it sits:
// a revolute joint in velocity mode whose nearest body ancestor is a body,
// whose z axis (its rotation axis) is horizontal in that body's plane frame,
// and that has a non-dynamic cylinder or sphere child giving the wheel radius
// R. It drives along forward = axis x up with surface speed
// target_velocity * R (box2d_backend.h: the sign convention). Engine-neutral.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "framework/scene.h"
#include "modules/dynamics/scene_walk.h"

namespace swarmsim::dynamics {

// A wheel axis counts as horizontal when its vertical component is below this
// (about 0.06 degrees of tilt).
inline constexpr double kWheelHorizontalTolerance = 1e-3;

// A wheel in its body's plane frame (origin at the body's centre, x along its
// heading), metres.
struct PlaneWheelGeometry {          // 48 bytes
  double p_x = 0, p_y = 0;           // contact point (the joint's position), m
  double f_x = 0, f_y = 0;           // unit forward direction (axis x up)
  double radius = 0;                 // m
  const ShapeData* shape = nullptr;  // the wheel (its friction)
};

// A wheel joint's wheel: its first non-dynamic round child, or null.
inline const ShapeData* WheelShapeOf(const Scene& scene, uint32_t joint_slot) {
  for (ObjectId child : scene.children(scene.IdAt(joint_slot))) {
    const ShapeData* shape = ShapeAt(scene, child.index());
    if (shape && !shape->dynamic && shape->kind != ShapeKind::kBox &&
        shape->kind != ShapeKind::kMesh && shape->size.x > 0)
      return shape;
  }
  return nullptr;
}

// Calls visit(joint_slot, joint, body, wheel) for every wheel of the scene, in
// joint slot order; `body_of` (slots) maps a slot to its body index, -1 where
// it has none, and `body_slot(body)` gives a body's scene slot.
template <class BodySlot, class Visit>
void ForEachPlaneWheel(const Scene& scene, const std::vector<int32_t>& body_of,
                       BodySlot&& body_slot, Visit&& visit) {
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    if (!scene.alive_at(s) || scene.type_at(s) != ObjectType::kJoint) continue;
    const JointData& joint = scene.joints()[scene.row_at(s)];
    if (joint.type() != JointType::kRevolute || joint.mode() != JointMode::kVelocity) continue;
    const int32_t b = NearestBodyAbove(scene, body_of, s, -1);
    if (b < 0) continue;
    const ShapeData* wheel_shape = WheelShapeOf(scene, s);
    if (!wheel_shape) continue;
    // Joint position and axis in the body's plane frame (yaw only).
    const Pose& X_WB = scene.world_pose_at(body_slot(static_cast<uint32_t>(b)));
    const Pose& X_WJ = scene.world_pose_at(s);
    const Quat q_PW = Quat::FromYaw(-X_WB.q.Yaw());
    const Vec3 p_BJ = q_PW.Rotate(X_WJ.p - X_WB.p);
    const Vec3 axis = q_PW.Rotate(X_WJ.q.Rotate({0, 0, 1}));
    if (std::abs(axis.z) > kWheelHorizontalTolerance) continue;
    const Vec3 forward = axis.Cross({0, 0, 1}).Normalized();  // (a_y, -a_x, 0)
    PlaneWheelGeometry wheel;
    wheel.p_x = p_BJ.x;
    wheel.p_y = p_BJ.y;
    wheel.f_x = forward.x;
    wheel.f_y = forward.y;
    wheel.radius = wheel_shape->size.x;
    wheel.shape = wheel_shape;
    visit(s, joint, static_cast<uint32_t>(b), wheel);
  }
}

}  // namespace swarmsim::dynamics
