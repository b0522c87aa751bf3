// PlaneWorld's moving surfaces (conveyor belts). In the top-down plane a
// body's support is not a contact but the ground friction model (a
// b2FrictionJoint pulling its velocity towards the ground's, zero). A body
// lying on a belt -- its centre over the belt's footprint, its bottom at the
// belt's top within kBeltGap -- has that friction pull it towards the belt's
// surface velocity at its centre instead, and its rotation towards the
// belt's turn (nonzero on a bend): the same Coulomb limits as its ground
// friction (mu m g and 2/3 mu m g r) with mu the geometric mean of the
// body's and the belt's friction (as contacts mix them), applied as
// impulses before the Box2D step, its friction joint off meanwhile.
// This is what b2Contact::SetTangentSpeed does for a contact in a side view,
// for the support contact a top-down plane models by friction. Bodies with
// wheels are not carried (their traction model assumes a still ground).
#include <box2d/b2_body.h>
#include <box2d/b2_friction_joint.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "framework/scene.h"
#include "modules/dynamics/box2d/plane_world.h"
#include "modules/dynamics/scene_walk.h"

namespace swarmsim::box2d {

namespace {

// How far a body's bottom may be from a belt's top and still lie on it, m.
constexpr double kBeltGap = 0.005;

}  // namespace

void PlaneWorld::BuildBelts(const Scene& scene, const std::vector<int32_t>& body_of) {
  const double L = scale_;
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    const ShapeData* shape = dynamics::ShapeAt(scene, s);
    if (!shape || shape->dynamic || !shape->HasMovingSurface() ||
        dynamics::NearestBodyAbove(scene, body_of, s, -1) >= 0)
      continue;
    const Pose& X_WS = scene.world_pose_at(s);
    PlaneBelt belt;
    belt.slot = s;
    belt.c_x = X_WS.p.x * L;
    belt.c_y = X_WS.p.y * L;
    const double yaw = X_WS.q.Yaw();
    belt.cos = std::cos(yaw);
    belt.sin = std::sin(yaw);
    // A box's footprint; any other shape's bounding square.
    const bool box = shape->kind == ShapeKind::kBox || shape->kind == ShapeKind::kMesh;
    belt.half_x = (box ? shape->size.x / 2 : shape->size.x) * L;
    belt.half_y = (box ? shape->size.y / 2 : shape->size.x) * L;
    belt.top = dynamics::CalcHeightRange(*shape, X_WS).hi;
    belt.friction = shape->friction;
    belts_.push_back(belt);
  }
}

void PlaneWorld::AddRider(const Scene& scene, uint32_t body, b2FrictionJoint* friction,
                          double max_force, double max_torque) {
  const uint32_t slot = bodies_[body].slot;
  PlaneRider rider;
  rider.body = body;
  rider.bottom =
      dynamics::CalcHeightRange(scene.shapes()[scene.row_at(slot)], scene.world_pose_at(slot)).lo;
  rider.friction = friction;
  rider.max_force = max_force;
  rider.max_torque = max_torque;
  rider.body_friction = scene.shapes()[scene.row_at(slot)].friction;
  riders_.push_back(rider);
}

void PlaneWorld::ReadBelts(const Scene& scene) {
  for (PlaneBelt& belt : belts_) {
    const Quat& q_WS = scene.world_pose_at(belt.slot).q;
    const ShapeData& shape = scene.shapes()[scene.row_at(belt.slot)];
    const Vec3 v_W = q_WS.Rotate(shape.surface_velocity);
    belt.v_x = v_W.x * scale_;
    belt.v_y = v_W.y * scale_;
    belt.w = q_WS.Rotate(shape.surface_angular_velocity).z;
  }
}

void PlaneWorld::ApplyBelts(double dt) {
  for (PlaneRider& rider : riders_) {
    b2Body* body = bodies_[rider.body].body;
    const b2Vec2& p = body->GetPosition();
    // The first belt (slot order) under the body's centre, at its bottom.
    int32_t on = -1;
    for (size_t k = 0; k < belts_.size() && on < 0; ++k) {
      const PlaneBelt& belt = belts_[k];
      if (std::abs(rider.bottom - belt.top) > kBeltGap) continue;
      const double dx = p.x - belt.c_x, dy = p.y - belt.c_y;
      const double x = belt.cos * dx + belt.sin * dy, y = -belt.sin * dx + belt.cos * dy;
      if (std::abs(x) <= belt.half_x && std::abs(y) <= belt.half_y) on = static_cast<int32_t>(k);
    }
    if ((on >= 0) != (rider.belt >= 0)) {
      rider.friction->SetMaxForce(on >= 0 ? 0.0f : static_cast<float>(rider.max_force));
      rider.friction->SetMaxTorque(on >= 0 ? 0.0f : static_cast<float>(rider.max_torque));
    }
    rider.belt = on;
    if (on < 0) continue;
    // The belt's surface at the body's centre: its velocity there, and its
    // turn (a bend's segment turns about the bend's centre).
    const PlaneBelt& belt = belts_[on];
    const double target_x = belt.v_x - belt.w * (p.y - belt.c_y);
    const double target_y = belt.v_y + belt.w * (p.x - belt.c_x);
    const b2Vec2& v = body->GetLinearVelocity();
    const double m = body->GetMass();
    double jx = m * (target_x - v.x), jy = m * (target_y - v.y);
    // Coulomb limits with the mixed friction: the ground's, scaled.
    const double mix = rider.body_friction > 0
                           ? std::sqrt(rider.body_friction * belt.friction) / rider.body_friction
                           : 0.0;
    const double cap = mix * rider.max_force * dt;
    const double norm = std::hypot(jx, jy);
    if (norm > cap) {
      jx *= cap / norm;
      jy *= cap / norm;
    }
    const double torque_cap = mix * rider.max_torque * dt;
    const double angular = std::clamp(body->GetInertia() * (belt.w - body->GetAngularVelocity()),
                                      -torque_cap, torque_cap);
    if (jx != 0 || jy != 0)
      body->ApplyLinearImpulseToCenter(b2Vec2(static_cast<float>(jx), static_cast<float>(jy)),
                                       true);
    if (angular != 0) body->ApplyAngularImpulse(static_cast<float>(angular), true);
  }
}

}  // namespace swarmsim::box2d
