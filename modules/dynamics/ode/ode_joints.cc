// The joints of OdeWorld (ode_world.h): built from the scene's joints
// (hinges, sliders, balls, screws as hinge + slider, fixed), linked to their
// masters (dependent joints), driven every substep (velocity, position
// servo, force, damping; a stop a motor drives its joint off released for
// that substep) and their positions tracked across ODE's angle wrap.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "framework/dependent_joints.h"
#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "modules/dynamics/ode/ode_internal.h"
#include "modules/dynamics/ode/ode_world.h"
#include "modules/dynamics/scene_walk.h"

namespace swarmsim::ode {

namespace {

using dynamics::PathAt;

// Position servo: motor velocity = kServoGain * error / dt (clamped).
constexpr double kServoGain = 0.5;
// ODE's "fudge factor" of a joint at a limit whose motor drives it away:
// ODE's default (1) applies too much force for one step, a jump (a Panda
// finger at its closed limit jumped 6.5 mm in its first 10 ms, at 0.2 m/s).
// 0 applies none of that excess (ApplyMotors releases the stop instead).
constexpr double kFudgeFactor = 0;

double WrapAngle(double a) {
  while (a > M_PI) a -= 2 * M_PI;
  while (a <= -M_PI) a += 2 * M_PI;
  return a;
}

// A wide hinge's stops (SimJoint::wide) around its reference; one released
// for this substep stays released. A stop more than pi away is never met:
// the reference moves before the joint gets there.
void SetHingeStops(const SimJoint& j) {
  dJointSetHingeParam(j.joint, dParamLoStop,
                      j.lo_released ? -dInfinity : j.min_position - j.offset);
  dJointSetHingeParam(j.joint, dParamHiStop, j.hi_released ? dInfinity : j.max_position - j.offset);
}

}  // namespace

void OdeWorld::LinkDependentJoints(const Scene& scene) {
  for (SimJoint& j : joints_) {
    const JointDependency* d = scene.joints()[j.row].depends();
    if (!d) continue;
    const uint32_t master_slot = JointMasterSlot(scene, j.slot);
    for (size_t k = 0; k < joints_.size(); ++k)
      if (joints_[k].slot == master_slot) {
        j.master = static_cast<int32_t>(k);
        j.master_factor = d->factor;
        j.master_offset = d->offset;
      }
  }
}

void OdeWorld::BuildJoints(const Scene& scene, const std::vector<dBodyID>& body_of) {
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    if (!scene.alive_at(s) || scene.type_at(s) != ObjectType::kJoint) continue;
    // Child: the first dynamic shape below, not across another joint.
    const int32_t child_slot = dynamics::FirstDynamicShapeBelow(scene, s);
    if (child_slot < 0) continue;  // stays kinematic
    // Parent: the nearest body above (dynamic or kinematic), else the world.
    AddJoint(scene, s, body_of[child_slot],
             dynamics::NearestBodyAbove<dBodyID>(scene, body_of, s, nullptr));
  }
}

void OdeWorld::AddJoint(const Scene& scene, uint32_t slot, dBodyID child, dBodyID parent) {
  const uint32_t row = scene.row_at(slot);
  const JointData& data = scene.joints()[row];
  const Pose& X_WJ = scene.world_pose_at(slot);
  const Vec3 axis = X_WJ.q.Rotate({0, 0, 1});
  SimJoint j{};
  j.slot = slot;
  j.row = row;
  j.min_position = data.settings->min_position;
  j.max_position = data.settings->max_position;
  j.offset = data.position;
  j.position = data.position;
  j.parent_body = parent;
  j.child_body = child;
  j.X_AJ = parent ? BodyPose(parent).Inverse() * X_WJ : X_WJ;
  j.q_JB0 = X_WJ.q.Conjugate() * BodyPose(child).q;
  j.ball0 = data.ball;
  const JointSettings& settings = *data.settings;
  // The limits' ERP and CFM: the joint's own, else the world's, else erp's and cfm's.
  const double limit_erp = settings.limit_erp >= 0   ? settings.limit_erp
                           : options_.limit_erp >= 0 ? options_.limit_erp
                                                     : options_.erp;
  const double limit_cfm = settings.limit_cfm >= 0   ? settings.limit_cfm
                           : options_.limit_cfm >= 0 ? options_.limit_cfm
                                                     : options_.cfm;
  switch (settings.type) {
    case JointType::kRevolute:
      j.joint = dJointCreateHinge(world_, nullptr);
      dJointAttach(j.joint, child, parent);
      dJointSetHingeAnchor(j.joint, X_WJ.p.x, X_WJ.p.y, X_WJ.p.z);
      dJointSetHingeAxis(j.joint, axis.x, axis.y, axis.z);
      // ODE's stops live in (-pi, pi] around the Build position; limits
      // beyond it are held around a reference that follows the joint.
      if (settings.min_position - j.offset >= -M_PI && settings.max_position - j.offset <= M_PI) {
        dJointSetHingeParam(j.joint, dParamLoStop, settings.min_position - j.offset);
        dJointSetHingeParam(j.joint, dParamHiStop, settings.max_position - j.offset);
        j.has_stops = true;
      } else if (std::isfinite(settings.min_position) || std::isfinite(settings.max_position)) {
        j.wide = j.has_stops = true;
        SetHingeStops(j);
      }
      dJointSetHingeParam(j.joint, dParamStopERP, limit_erp);
      dJointSetHingeParam(j.joint, dParamStopCFM, limit_cfm);
      dJointSetHingeParam(j.joint, dParamFudgeFactor, kFudgeFactor);
      j.last_angle = dJointGetHingeAngle(j.joint);
      break;
    case JointType::kPrismatic:
      j.joint = dJointCreateSlider(world_, nullptr);
      dJointAttach(j.joint, child, parent);
      dJointSetSliderAxis(j.joint, axis.x, axis.y, axis.z);
      if (std::isfinite(settings.min_position))
        dJointSetSliderParam(j.joint, dParamLoStop, settings.min_position - j.offset);
      if (std::isfinite(settings.max_position))
        dJointSetSliderParam(j.joint, dParamHiStop, settings.max_position - j.offset);
      j.has_stops = true;
      dJointSetSliderParam(j.joint, dParamStopERP, limit_erp);
      dJointSetSliderParam(j.joint, dParamStopCFM, limit_cfm);
      dJointSetSliderParam(j.joint, dParamFudgeFactor, kFudgeFactor);
      break;
    case JointType::kSpherical:
      j.joint = dJointCreateBall(world_, nullptr);
      dJointAttach(j.joint, child, parent);
      dJointSetBallAnchor(j.joint, X_WJ.p.x, X_WJ.p.y, X_WJ.p.z);
      break;
    case JointType::kScrew:
      // ODE has no screw joint: one between bodies it simulates is refused
      // (a screw joint whose children are not dynamic moves kinematically).
      throw Error("ode: screw joint '" + PathAt(scene, slot) +
                  "' moves a dynamic body: screw joints need kinematic physics "
                  "(physics: kinematic), or children that are not dynamic");
    case JointType::kFixed:
      j.joint = dJointCreateFixed(world_, nullptr);
      dJointAttach(j.joint, child, parent);
      dJointSetFixed(j.joint);
      break;
  }
  joints_.push_back(j);
}

void OdeWorld::ApplyMotors(double dt) {
  // Independent joints first, then the dependent ones, which follow where
  // their masters are in this substep at the speed their masters are driven.
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t k = 0; k < joints_.size(); ++k) {
      SimJoint& j = joints_[k];
      const JointCommand& c = commands_[k];
      const bool hinge = c.type == JointType::kRevolute;
      if (!hinge && c.type != JointType::kPrismatic) continue;
      if ((j.master >= 0) != (pass == 1)) continue;
      double velocity = 0, max_force = 0;
      if (j.master >= 0) {
        // A servo on the master's position (every substep: a mimic finger
        // does not lag its master by a control step), whatever its mode: the
        // master's speed times the factor, plus a correction of at most its
        // own max_velocity.
        const SimJoint& m = joints_[static_cast<size_t>(j.master)];
        const double target = j.master_offset + j.master_factor * m.position;
        velocity =
            j.master_factor * motor_velocity_[static_cast<size_t>(j.master)] +
            std::clamp(kServoGain * (target - j.position) / dt, -c.max_velocity, c.max_velocity);
        max_force = c.max_force;
      } else {
        switch (c.mode) {
          case JointMode::kVelocity:
            velocity = c.target_velocity;
            max_force = c.max_force;
            break;
          case JointMode::kPosition:
            velocity = std::clamp(kServoGain * (c.target_position - j.position) / dt,
                                  -c.max_velocity, c.max_velocity);
            max_force = c.max_force;
            break;
          case JointMode::kForce:
            if (hinge)
              dJointAddHingeTorque(j.joint, c.target_force);
            else
              dJointAddSliderForce(j.joint, c.target_force);
            break;
          case JointMode::kPassive: break;
        }
      }
      // What a dependent joint's feed-forward takes: the motor's speed, or
      // the joint's own for one without a motor.
      motor_velocity_[k] = max_force > 0 ? velocity
                           : hinge       ? dJointGetHingeAngleRate(j.joint)
                                         : dJointGetSliderPositionRate(j.joint);
      // Viscous damping (a URDF joint's <dynamics damping>), in every mode.
      if (c.damping > 0) {
        if (hinge)
          dJointAddHingeTorque(j.joint, -c.damping * dJointGetHingeAngleRate(j.joint));
        else
          dJointAddSliderForce(j.joint, -c.damping * dJointGetSliderPositionRate(j.joint));
      }
      // A motor driving the joint off a stop it rests on: ODE turns the
      // motor into a push of max_force times the fudge factor (0 here: 1
      // made a Panda finger jump), so the joint stayed on the stop for good
      // under the exact solver (a Panda's joint4 starts on its upper limit;
      // commanded to -1 rad it never moved). For this substep that stop is
      // released and the motor works as anywhere else; the next substep
      // holds the stop again.
      // A wide hinge's reference moved to where it is when it comes within
      // pi/2 of a stop ODE cannot hold from the reference (more than pi
      // away), or 3 pi/4 from the reference (the angle ODE measures wraps
      // at pi). A joint that goes neither way is stepped as before.
      // (Asked of wide hinges only: every joint passes here every substep.)
      const auto near_far_stop = [&j] {
        return (j.min_position - j.offset < -M_PI && j.position - j.min_position < M_PI / 2) ||
               (j.max_position - j.offset > M_PI && j.max_position - j.position < M_PI / 2);
      };
      if (j.wide && (near_far_stop() || std::abs(j.position - j.offset) > 0.75 * M_PI)) {
        dVector3 axis;
        dJointGetHingeAxis(j.joint, axis);
        dJointSetHingeAxis(j.joint, axis[0], axis[1], axis[2]);  // the angle reads 0 here
        j.offset = j.position;
        j.last_angle = dJointGetHingeAngle(j.joint);
        SetHingeStops(j);
      }
      if (j.has_stops) {
        // Resting on it: within kOnStop of it, either side (a joint pushed
        // past it keeps it, to be pushed back; a motor holding the joint
        // on it, moving it less than kOnStop a substep, keeps it too).
        constexpr double kOnStop = 1e-6;  // rad or m
        const bool drives = max_force > 0 && std::abs(velocity) * dt > kOnStop;
        const bool release_hi =
            drives && velocity < 0 && std::abs(j.position - j.max_position) <= kOnStop;
        const bool release_lo =
            drives && velocity > 0 && std::abs(j.position - j.min_position) <= kOnStop;
        const int param[2] = {dParamLoStop, dParamHiStop};
        const bool release[2] = {release_lo, release_hi};
        bool* released[2] = {&j.lo_released, &j.hi_released};
        const double stop[2] = {j.min_position - j.offset, j.max_position - j.offset};
        for (int side = 0; side < 2; ++side) {
          if (release[side] == *released[side]) continue;
          const double value = release[side] ? (side == 0 ? -dInfinity : dInfinity) : stop[side];
          if (hinge)
            dJointSetHingeParam(j.joint, param[side], value);
          else
            dJointSetSliderParam(j.joint, param[side], value);
          *released[side] = release[side];
        }
      }
      if (hinge) {
        dJointSetHingeParam(j.joint, dParamVel, velocity);
        dJointSetHingeParam(j.joint, dParamFMax, max_force);
      } else {
        dJointSetSliderParam(j.joint, dParamVel, velocity);
        dJointSetSliderParam(j.joint, dParamFMax, max_force);
      }
    }
  }
}

void OdeWorld::TrackJointPositions() {
  // Each joint reads its bodies and writes only its own row: on every thread.
  auto track = [this](int64_t begin, int64_t end) {
    for (int64_t k = begin; k < end; ++k) {
      SimJoint& j = joints_[static_cast<size_t>(k)];
      switch (commands_[static_cast<size_t>(k)].type) {
        case JointType::kRevolute: {
          const double a = dJointGetHingeAngle(j.joint);
          j.position += WrapAngle(a - j.last_angle);
          j.last_angle = a;
          break;
        }
        case JointType::kPrismatic: j.position = j.offset + dJointGetSliderPosition(j.joint); break;
        case JointType::kSpherical:
        case JointType::kScrew:
        case JointType::kFixed: break;
      }
    }
  };
  constexpr int64_t kGrain = 1024;
  const int64_t n = static_cast<int64_t>(joints_.size());
  if (settings_.scheduler)
    settings_.scheduler->ParallelFor(0, n, kGrain, track);
  else
    track(0, n);
}

}  // namespace swarmsim::ode
