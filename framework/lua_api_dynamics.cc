// sim.* dynamics: the hybrid switch between dynamic and kinematic shapes,
// and joint forces (force mode).
//
// sim.setObjectDynamic changes what the dynamics backend simulates, a
// structural change, so it is always queued (RobotRuntime::deferred) and
// applied by the World after the control phase, in handle order: scripts of
// all robots see the same flags during the phase and the result does not
// depend on the thread schedule. The backend rebuilds at the next physics
// step, keeping velocities.
#include <cmath>
#include <cstdio>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

// sim.setObjectDynamic(h, dynamic): a shape becomes dynamic (simulated) or
// kinematic (moved by scripts, IK and joints) from the next physics step.
int SetObjectDynamic(lua_State* L) {
  const LuaContext& c = Context(L);
  const ObjectId id = CheckObject(L, 1);
  ArgType(L, 2, LUA_TBOOLEAN);
  c.scene->shape(id);  // validates: a shape, not stale
  PushDeferredWrite(L, {id, DeferredWrite::Kind::kShapeDynamic, lua_toboolean(L, 2) ? 1.0 : 0.0});
  return 0;
}

// sim.isObjectDynamic(h) -> bool, as of the start of the phase.
int IsObjectDynamic(lua_State* L) {
  const LuaContext& c = Context(L);
  lua_pushboolean(L, c.scene->shape(CheckObject(L, 1)).dynamic);
  return 1;
}

// sim.setJointTargetForce(h, f): N or N m applied by a force-mode joint
// (own robot's joints, or any joint from a scene script).
int SetJointTargetForce(lua_State* L) {
  const LuaContext& c = Context(L);
  const ObjectId id = CheckObject(L, 1);
  const double value = ArgNumber(L, 2);
  JointData& joint = c.scene->mutable_joint(id);
  if (!std::isfinite(value)) throw Error("the force is not a finite number");
  // Far past any motor; beyond it the engines' arithmetic overflows (ODE
  // stopped on an internal assertion at 1e300).
  if (std::abs(value) > 1e15) {
    char text[96];
    std::snprintf(text, sizeof text, "the force %g is beyond +-1e15 (N or N m)", value);
    throw Error(text);
  }
  if (c.instance >= 0 && c.scene->instance_of(id) != c.instance)
    throw Error("joint '" + c.scene->PathOf(id) +
                "' belongs to another robot; only its own scripts can set its force");
  joint.target_force = value;
  return 0;
}

}  // namespace

void RegisterDynamicsApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setObjectDynamic", Guarded<SetObjectDynamic, "sim.setObjectDynamic">},
      {"isObjectDynamic", Guarded<IsObjectDynamic, "sim.isObjectDynamic">},
      {"setJointTargetForce", Guarded<SetJointTargetForce, "sim.setJointTargetForce">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim
