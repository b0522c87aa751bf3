// PlaneWorld: stepping (traction, Box2D), write-back and hashing. Build is in
// plane_world_build.cc, force sensors in plane_force_sensors.cc.
#include "modules/dynamics/box2d/plane_world.h"

#include <box2d/b2_body.h>
#include <box2d/b2_contact.h>
#include <box2d/b2_joint.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/state_hash.h"

namespace swarmsim::box2d {

namespace {

// Traction passes stop when no wheel's impulse changes by more than this
// fraction of its Coulomb limit.
constexpr double kConverged = 1e-6;

// True when `q` is (s, c) bit for bit (so +0 and -0 differ: atan2 tells them
// apart) and not NaN (the "not known" mark).
bool SameRotation(const b2Rot& q, float s, float c) {
  return q.s == s && q.c == c && std::bit_cast<uint32_t>(q.s) == std::bit_cast<uint32_t>(s) &&
         std::bit_cast<uint32_t>(q.c) == std::bit_cast<uint32_t>(c);
}

}  // namespace

bool Box2dOverridesAreInPlace();  // b2_overrides.cc

PlaneWorld::PlaneWorld(const Options& options, const DynamicsSettings& settings)
    : options_(options), settings_(settings), scale_(options.length_scale) {
  // Keeps the free timers and the checked allocator linked in (see b2_overrides.cc).
  static const bool overridden = Box2dOverridesAreInPlace();
  (void)overridden;
  if (!(scale_ > 0) || !std::isfinite(scale_))
    throw Error("box2d: length_scale must be a positive number, got " + std::to_string(scale_));
  // Gravity only sets ground friction here; zero makes the ground frictionless.
  if (!(settings_.gravity >= 0) || !std::isfinite(settings_.gravity))
    throw Error("box2d: gravity must be a non-negative number (it sets ground friction), got " +
                std::to_string(settings_.gravity));
}

PlaneWorld::~PlaneWorld() = default;

void PlaneWorld::SyncFromScene(const Scene& scene, double /*duration*/) {
  const double L = scale_;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    PlaneBodyPose& pose = body_poses_[b];
    const Pose& X_WB = scene.world_pose_at(bodies_[b].slot);
    if (X_WB == pose.X_WB_last) continue;
    const double yaw = X_WB.q.Yaw();
    b2Body* body = bodies_[b].body;
    body->SetTransform(b2Vec2(static_cast<float>(X_WB.p.x * L), static_cast<float>(X_WB.p.y * L)),
                       static_cast<float>(yaw));
    body->SetAwake(true);
    bodies_[b].dv_x = bodies_[b].dv_y = bodies_[b].dw = 0;
    pose.z = X_WB.p.z;
    pose.q_tilt = (Quat::FromYaw(-yaw) * X_WB.q).Normalized();
    pose.X_WB_last = X_WB;
    pose.rot_s = pose.rot_c = std::numeric_limits<float>::quiet_NaN();  // not from Box2D
  }
}

void PlaneWorld::ReadCommands(const Scene& scene) {
  for (uint32_t b : wheeled_) bodies_[b].commanded = false;
  for (PlaneWheel& wheel : wheels_) {
    const JointData& joint = scene.joints()[scene.row_at(wheel.joint_slot)];
    const double target = joint.mode() == JointMode::kVelocity ? joint.DriveVelocity() : 0.0;
    wheel.surface_speed = target * wheel.radius_m * scale_;
    if (target != 0) bodies_[wheel.body].commanded = true;
  }
  if (!belts_.empty()) ReadBelts(scene);
}

namespace {

// Projected Gauss-Seidel over one body's wheels: one pass. (vx, vy, w) in
// `solve` is the body velocity in its plane frame, Box2D units. Each wheel
// gets the impulse that makes its contact point move at the desired
// velocity, its accumulated impulse clamped to its Coulomb circle and then to
// its motor limit along forward. Leaves the impulses in wheel->acc_*. True
// when no impulse changed by more than kConverged of its Coulomb limit (a
// robot driving freely at its command needs one pass).
bool SolveWheelsPass(PlaneWheel* first, PlaneWheel* last, double dt, TractionSolve* solve) {
  const double im = solve->inverse_mass, ii = solve->inverse_inertia;
  double vx = solve->vx, vy = solve->vy, w = solve->w;
  bool converged = true;
  for (PlaneWheel* wheel = first; wheel != last; ++wheel) {
    // Velocity error at the contact point: desired (forward at the surface
    // speed, nothing sideways) minus actual and the predicted lag.
    const double forward = wheel->surface_speed - wheel->lag;
    const double ex = forward * wheel->f_x - (vx - w * wheel->p_y);
    const double ey = forward * wheel->f_y - (vy + w * wheel->p_x);
    const double old_x = wheel->acc_x, old_y = wheel->acc_y;
    double ax = old_x + wheel->k_xx * ex + wheel->k_xy * ey;
    double ay = old_y + wheel->k_xy * ex + wheel->k_yy * ey;
    // Coulomb limit on the whole, then the motor limit on the forward part.
    const double limit = wheel->coulomb_rate * dt;
    const double norm2 = ax * ax + ay * ay;
    if (norm2 > limit * limit) {
      // hypot when the square overflowed (absurd targets, e.g. 1e200 rad/s):
      // still saturate, rather than scale by limit / inf = 0 and stall.
      const double k = limit / (std::isfinite(norm2) ? std::sqrt(norm2) : std::hypot(ax, ay));
      ax *= k;
      ay *= k;
    }
    const double motor = wheel->motor_rate * dt;
    const double along = ax * wheel->f_x + ay * wheel->f_y;
    const double excess = along > motor ? along - motor : (along < -motor ? along + motor : 0);
    ax -= excess * wheel->f_x;
    ay -= excess * wheel->f_y;
    wheel->acc_x = ax;
    wheel->acc_y = ay;
    const double ix = ax - old_x, iy = ay - old_y;
    vx += im * ix;
    vy += im * iy;
    w += ii * (wheel->p_x * iy - wheel->p_y * ix);
    if (std::abs(ix) + std::abs(iy) > kConverged * limit) converged = false;
  }
  solve->vx = vx;
  solve->vy = vy;
  solve->w = w;
  return converged;
}

}  // namespace

void PlaneWorld::ApplyTraction(double dt) {
  // Wheeled bodies go through in blocks of kTractionBlock: the block's
  // Gauss-Seidel passes interleave its bodies (see 2. below), and a block's
  // Box2D bodies and wheels are still in cache when the impulses are applied.
  for (size_t next = 0; next < wheeled_.size();) {
    const size_t end = std::min(wheeled_.size(), next + kTractionBlock);
    ApplyTraction(std::span<const uint32_t>(wheeled_).subspan(next, end - next), dt);
    next = end;
  }
}

void PlaneWorld::ApplyTraction(std::span<const uint32_t> wheeled, double dt) {
  const int passes = std::max(1, options_.traction_iterations);
  // 1. Each awake body's velocity and last step's contact change, in its
  // plane frame. The contact change, projected on each wheel's forward
  // direction, counts as velocity the wheel must make up (a warm start):
  // without it a robot pushing an object lags one step of contact impulse
  // behind its command. Only the forward part: sideways, the same feedback
  // would keep adding a wall's push-back to the error and leave a saturated
  // wheel no grip to slide along the wall with.
  //   (Fields are written in place: a struct built on the stack and copied
  // in was read back before its stores had landed, a stall per body.)
  size_t count = 0;
  for (uint32_t b : wheeled) {
    PlaneBody& plane_body = bodies_[b];
    b2Body* body = plane_body.body;
    // A commanded robot stays awake; an idle one at rest may sleep.
    if (plane_body.commanded) {
      body->SetAwake(true);
    } else if (!body->IsAwake()) {
      plane_body.v_traction.SetZero();  // asleep: at rest
      plane_body.w_traction = 0;
      plane_body.dv_x = plane_body.dv_y = plane_body.dw = 0;
      continue;
    }
    const b2Rot& rot = body->GetTransform().q;
    const double c = rot.c, s = rot.s;
    const b2Vec2& v = body->GetLinearVelocity();
    TractionSolve& solve = traction_[count++];
    solve.body = b;
    solve.converged = false;
    solve.c = c;
    solve.s = s;
    solve.inverse_mass = plane_body.inverse_mass;
    solve.inverse_inertia = plane_body.inverse_inertia;
    solve.vx = c * v.x + s * v.y;
    solve.vy = -s * v.x + c * v.y;
    solve.w = body->GetAngularVelocity();
    const double dv_x = plane_body.dv_x, dv_y = plane_body.dv_y;
    const double dx = c * dv_x + s * dv_y, dy = -s * dv_x + c * dv_y, dw = plane_body.dw;
    PlaneWheel* const first = wheels_.data() + plane_body.first_wheel;
    for (PlaneWheel* wheel = first; wheel != first + plane_body.wheel_count; ++wheel) {
      wheel->acc_x = wheel->acc_y = 0;
      const double cx = dx - dw * wheel->p_y, cy = dy + dw * wheel->p_x;
      wheel->lag = cx * wheel->f_x + cy * wheel->f_y;
    }
  }
  const std::span<TractionSolve> solves(traction_.data(), count);
  // 2. Gauss-Seidel passes, each over the bodies not yet converged. A body's
  // pass is a chain of dependent multiply-adds; bodies are independent, so
  // looping over bodies inside a pass lets the CPU overlap their chains
  // (solving one body to convergence before the next kept it waiting on one
  // chain at a time). Each body's arithmetic, and so every result, is the
  // same either way.
  for (int pass = 0; pass < passes; ++pass) {
    bool all_converged = true;
    for (TractionSolve& solve : solves) {
      if (solve.converged) continue;
      const PlaneBody& plane_body = bodies_[solve.body];
      PlaneWheel* const first = wheels_.data() + plane_body.first_wheel;
      solve.converged = SolveWheelsPass(first, first + plane_body.wheel_count, dt, &solve);
      all_converged = all_converged && solve.converged;
    }
    if (all_converged) break;
  }
  // 3. Apply each body's total to it, in the world frame.
  for (const TractionSolve& solve : solves) {
    PlaneBody& plane_body = bodies_[solve.body];
    b2Body* body = plane_body.body;
    const double c = solve.c, s = solve.s;
    const PlaneWheel* const first = wheels_.data() + plane_body.first_wheel;
    double px = 0, py = 0, angular = 0;
    for (const PlaneWheel* wheel = first; wheel != first + plane_body.wheel_count; ++wheel) {
      px += wheel->acc_x;
      py += wheel->acc_y;
      angular += wheel->p_x * wheel->acc_y - wheel->p_y * wheel->acc_x;
    }
    if (px != 0 || py != 0 || angular != 0) {
      body->ApplyLinearImpulseToCenter(
          b2Vec2(static_cast<float>(c * px - s * py), static_cast<float>(s * px + c * py)), false);
      body->ApplyAngularImpulse(static_cast<float>(angular), false);
    }
    plane_body.v_traction = body->GetLinearVelocity();
    plane_body.w_traction = body->GetAngularVelocity();
  }
}

void PlaneWorld::Substep(double dt, double /*fraction*/) {
  last_dt_ = dt;
  ApplyTraction(dt);
  if (!riders_.empty()) ApplyBelts(dt);
  world_->Step(static_cast<float>(dt), options_.velocity_iterations, options_.position_iterations);
  // What the step (contacts) did to each wheeled body's velocity.
  for (uint32_t b : wheeled_) {
    PlaneBody& plane_body = bodies_[b];
    const b2Body* body = plane_body.body;
    if (!body->IsAwake()) {
      plane_body.dv_x = plane_body.dv_y = plane_body.dw = 0;
      continue;
    }
    const b2Vec2& v = body->GetLinearVelocity();
    plane_body.dv_x = v.x - plane_body.v_traction.x;
    plane_body.dv_y = v.y - plane_body.v_traction.y;
    plane_body.dw = body->GetAngularVelocity() - plane_body.w_traction;
  }
}

void PlaneWorld::WriteBack(Scene* scene) {
  if (!force_sensors_.empty()) ReadForceSensors(scene);
  const double inv_L = 1.0 / scale_;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const b2Body* body = bodies_[b].body;
    PlaneBodyPose& pose = body_poses_[b];
    const b2Transform& X = body->GetTransform();
    Pose X_WB;
    X_WB.p = {X.p.x * inv_L, X.p.y * inv_L, pose.z};
    if (SameRotation(X.q, pose.rot_s, pose.rot_c)) {
      // Not turned since the last write (a robot driving straight, a body
      // at rest: most of them in a diffusion run): the same rotation as
      // then, without the atan2 and sin/cos.
      X_WB.q = pose.X_WB_last.q;
    } else {
      const double yaw = std::atan2(static_cast<double>(X.q.s), static_cast<double>(X.q.c));
      X_WB.q = Quat::FromYaw(yaw) * pose.q_tilt;
      pose.rot_s = X.q.s;
      pose.rot_c = X.q.c;
    }
    const b2Vec2& v = body->GetLinearVelocity();
    scene->SetSimulatedState(bodies_[b].slot, X_WB, {v.x * inv_L, v.y * inv_L, 0},
                             {0, 0, body->GetAngularVelocity()});
    pose.X_WB_last = X_WB;
  }
}

void PlaneWorld::Hash(StateHasher* hasher) const {
  // Bodies: float state (unwrapped angle included) and sleep state.
  for (const PlaneBody& plane_body : bodies_) {
    const b2Body* body = plane_body.body;
    hasher->AddValue(body->GetPosition().x);
    hasher->AddValue(body->GetPosition().y);
    hasher->AddValue(body->GetAngle());
    hasher->AddValue(body->GetLinearVelocity().x);
    hasher->AddValue(body->GetLinearVelocity().y);
    hasher->AddValue(body->GetAngularVelocity());
    hasher->AddValue(static_cast<uint8_t>(body->IsAwake()));
  }
  // Contacts: the warm-start impulses.
  for (const b2Contact* contact = world_->GetContactList(); contact; contact = contact->GetNext()) {
    const b2Manifold* manifold = contact->GetManifold();
    hasher->AddValue(static_cast<uint8_t>(contact->IsTouching()));
    hasher->AddValue(manifold->pointCount);
    for (int i = 0; i < manifold->pointCount; ++i) {
      hasher->AddValue(manifold->points[i].normalImpulse);
      hasher->AddValue(manifold->points[i].tangentImpulse);
    }
  }
  // Ground friction joints: their warm-start impulses.
  for (const b2Joint* joint = world_->GetJointList(); joint; joint = joint->GetNext()) {
    const b2Vec2 force = joint->GetReactionForce(1.0f);
    hasher->AddValue(force.x);
    hasher->AddValue(force.y);
    hasher->AddValue(joint->GetReactionTorque(1.0f));
  }
}

}  // namespace swarmsim::box2d
