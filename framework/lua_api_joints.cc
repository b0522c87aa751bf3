// sim.* joints: targets (writes) and states (reads).
//
// A script writes its own robot's joints directly (only its worker touches
// them). A write to another robot's joint, or from a robot to a scene joint,
// is queued in RobotRuntime::deferred and applied by the World after the
// control phase in handle order, so the result does not depend on which
// robot ran first. Scene scripts run alone and write directly.
#include <cmath>
#include <cstdio>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

constexpr lua_Integer kJointIkActive = 0, kJointIkFrozen = 1;

bool OwnsJoint(const LuaContext& c, uint32_t slot) {
  return c.instance < 0 || c.scene->instance_of_at(slot) == c.instance;
}

// The joint at argument 1, validated (a wrong type or a stale handle throws
// with the Scene's message).
JointData& CheckJoint(lua_State* L, uint32_t* slot) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  scene.joint(id);  // validates
  *slot = id.index();
  return scene.joints()[scene.row_at(*slot)];
}

// A position of `joint` past what a world may use: a prismatic joint's
// (m), or a screw joint's advance (pitch x q).
void CheckJointReach(const JointData& joint, double q, const char* what) {
  const double reach = joint.type() == JointType::kPrismatic ? std::abs(q)
                       : joint.type() == JointType::kScrew   ? std::abs(q * joint.settings->pitch)
                                                             : 0;
  if (!(reach <= kMaxCoordinate)) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "the %s %g moves the joint's children %g m, beyond the 1e6 m a world may use",
                  what, q, reach);
    throw Error(text);
  }
}

void SetJointTarget(lua_State* L, DeferredWrite::Kind kind) {
  const LuaContext& c = Context(L);
  uint32_t slot = 0;
  JointData& joint = CheckJoint(L, &slot);
  const double value = ArgNumber(L, 2);
  if (!std::isfinite(value)) throw Error("the target is not a finite number");
  if (kind == DeferredWrite::Kind::kJointTargetPosition)
    CheckJointReach(joint, value, "target position");
  if (OwnsJoint(c, slot)) {
    if (kind == DeferredWrite::Kind::kJointTargetVelocity)
      joint.target_velocity = value;
    else
      joint.target_position = value;
  } else {
    PushDeferredWrite(L, {c.scene->IdAt(slot), kind, value});
  }
}

// sim.setJointTargetVelocity(h, v): rad/s or m/s, velocity-mode joints.
int SetJointTargetVelocity(lua_State* L) {
  SetJointTarget(L, DeferredWrite::Kind::kJointTargetVelocity);
  return 0;
}

// sim.setJointTargetPosition(h, p): rad or m, position-mode joints.
int SetJointTargetPosition(lua_State* L) {
  SetJointTarget(L, DeferredWrite::Kind::kJointTargetPosition);
  return 0;
}

// sim.setJointPosition(h, q): rad or m, joints no dynamics backend simulates
// (kinematic physics, or children that are not dynamic). Other robots read
// positions during the control phase, so a robot's write is applied after
// it (a scene script's at once): getJointPosition shows it next step.
int SetJointPosition(lua_State* L) {
  const LuaContext& c = Context(L);
  uint32_t slot = 0;
  JointData& joint = CheckJoint(L, &slot);
  const double value = ArgNumber(L, 2);
  const std::string path = c.scene->PathOf(c.scene->IdAt(slot));
  if (!std::isfinite(value)) throw Error("the position is not a finite number");
  if (joint.simulated)
    throw Error("joint '" + path +
                "' is simulated by the dynamics: use sim.setJointTargetPosition (position "
                "mode) or sim.setJointTargetVelocity");
  if (joint.depends())
    throw Error("joint '" + path + "' follows its master '" + joint.depends()->master +
                "': set the master's position");
  if (joint.type() == JointType::kSpherical || joint.type() == JointType::kFixed)
    throw Error("joint '" + path + "' is " + ToString(joint.type()) + ": it has no position");
  CheckJointReach(joint, value, "position");
  if (c.instance < 0)
    joint.JumpTo(value);
  else
    PushDeferredWrite(L, {c.scene->IdAt(slot), DeferredWrite::Kind::kJointPosition, value});
  return 0;
}

// sim.getJointPosition(h) -> rad or m, as of the start of the phase.
int GetJointPosition(lua_State* L) {
  uint32_t slot = 0;
  lua_pushnumber(L, CheckJoint(L, &slot).position);
  return 1;
}

// sim.getJointVelocity(h) -> rad/s or m/s, as of the start of the phase.
int GetJointVelocity(lua_State* L) {
  uint32_t slot = 0;
  lua_pushnumber(L, CheckJoint(L, &slot).velocity);
  return 1;
}

// Targets change during the control phase, so only the joint's own robot
// (or a scene script) may read them: anything else would race with the
// owner and depend on the thread schedule.
double ReadOwnTarget(lua_State* L, DeferredWrite::Kind kind) {
  const LuaContext& c = Context(L);
  uint32_t slot = 0;
  const JointData& joint = CheckJoint(L, &slot);
  if (!OwnsJoint(c, slot))
    throw Error("joint '" + c.scene->PathOf(c.scene->IdAt(slot)) +
                "' belongs to another robot; only its own scripts can read its target");
  return kind == DeferredWrite::Kind::kJointTargetVelocity ? joint.target_velocity
                                                           : joint.target_position;
}

// sim.getJointTargetVelocity(h) -> the target set so far (own robot only).
int GetJointTargetVelocity(lua_State* L) {
  lua_pushnumber(L, ReadOwnTarget(L, DeferredWrite::Kind::kJointTargetVelocity));
  return 1;
}

// sim.getJointTargetPosition(h) -> the target set so far (own robot only).
int GetJointTargetPosition(lua_State* L) {
  lua_pushnumber(L, ReadOwnTarget(L, DeferredWrite::Kind::kJointTargetPosition));
  return 1;
}

// sim.setJointIkMode(h, mode): sim.jointikmode_active (IK groups move the
// joint) or sim.jointikmode_frozen (they keep its value). The robot's own
// joints (or any from a scene script); IK reads it in the actuate phase.
int SetJointIkMode(lua_State* L) {
  const LuaContext& c = Context(L);
  uint32_t slot = 0;
  JointData& joint = CheckJoint(L, &slot);
  const lua_Integer mode = ArgInteger(L, 2);
  if (mode != kJointIkActive && mode != kJointIkFrozen)
    throw Error("bad argument #2 (sim.jointikmode_active or sim.jointikmode_frozen expected, got " +
                std::to_string(mode) + ")");
  if (!OwnsJoint(c, slot))
    throw Error("joint '" + c.scene->PathOf(c.scene->IdAt(slot)) +
                "' belongs to another robot; only its own scripts can set its IK mode");
  joint.ik_frozen = mode == kJointIkFrozen;
  return 0;
}

// sim.getJointIkMode(h) -> sim.jointikmode_active or sim.jointikmode_frozen
// (own robot only: its scripts may change it during the phase).
int GetJointIkMode(lua_State* L) {
  const LuaContext& c = Context(L);
  uint32_t slot = 0;
  const JointData& joint = CheckJoint(L, &slot);
  if (!OwnsJoint(c, slot))
    throw Error("joint '" + c.scene->PathOf(c.scene->IdAt(slot)) +
                "' belongs to another robot; only its own scripts can read its IK mode");
  lua_pushinteger(L, joint.ik_frozen ? kJointIkFrozen : kJointIkActive);
  return 1;
}

}  // namespace

void RegisterJointsApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setJointTargetVelocity", Guarded<SetJointTargetVelocity, "sim.setJointTargetVelocity">},
      {"setJointTargetPosition", Guarded<SetJointTargetPosition, "sim.setJointTargetPosition">},
      {"setJointPosition", Guarded<SetJointPosition, "sim.setJointPosition">},
      {"getJointPosition", Guarded<GetJointPosition, "sim.getJointPosition">},
      {"getJointVelocity", Guarded<GetJointVelocity, "sim.getJointVelocity">},
      {"getJointTargetVelocity", Guarded<GetJointTargetVelocity, "sim.getJointTargetVelocity">},
      {"getJointTargetPosition", Guarded<GetJointTargetPosition, "sim.getJointTargetPosition">},
      {"setJointIkMode", Guarded<SetJointIkMode, "sim.setJointIkMode">},
      {"getJointIkMode", Guarded<GetJointIkMode, "sim.getJointIkMode">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
  lua_pushinteger(L, kJointIkActive);
  lua_setfield(L, -2, "jointikmode_active");
  lua_pushinteger(L, kJointIkFrozen);
  lua_setfield(L, -2, "jointikmode_frozen");
}

}  // namespace swarmsim
