// sim.* paths (the Lua area of the path type), CoppeliaSim's names:
//   sim.getPathLength(h) -> m
//   sim.getPathPose(h, s) -> {x, y, z, qx, qy, qz, qw}, world frame, at arc length s
//   sim.getPathPosition(h) -> m, where the path's followers are (as of the
//     step's start: it changes in the actuate phase only)
//   sim.setPathPosition(h, s) (applied in the actuate phase, before this
//     step's motion), sim.setPathVelocity(h, v) (m/s)
// `h` is a path, or one of its children (a follower). A script sets only its
// own robot's paths (a scene script any), so the result never depends on
// which robot ran first; the followers move in the actuate phase.
// Conveyors (the conveyor type's area):
//   sim.getConveyorSpeed(h) -> m/s, the belt's speed as of the step's start
//   sim.setConveyorSpeed(h, v): m/s along its points (negative: backwards),
//     applied in the actuate phase (so every robot reads the same speed in
//     a step); only the conveyor's own robot's scripts (or a scene script)
//     may set it
// `h` is a conveyor or one of its children (a belt segment).
#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/paths/rows.h"
#include "modules/paths/types.h"

namespace swarmsim::paths {

namespace {

// The path at argument 1 (or the parent path of the object there).
PathRow& PathArg(lua_State* L, uint32_t* slot) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  *slot = scene.SlotOf(id);
  ObjectType type;
  if (!scene.FindType(kTypeName, &type)) throw Error("paths are not available in this world");
  if (scene.type_at(*slot) != type) {
    const int32_t parent = scene.parent_at(*slot);
    if (parent < 0 || scene.type_at(static_cast<uint32_t>(parent)) != type)
      throw Error("object " + scene.PathOf(id) + " is neither a path nor a path's child");
    *slot = static_cast<uint32_t>(parent);
  }
  return static_cast<Rows<PathRow>&>(*scene.rows(type)).rows[scene.row_at(*slot)];
}

PathRow& OwnPathArg(lua_State* L) {
  const LuaContext& c = Context(L);
  uint32_t slot = 0;
  PathRow& p = PathArg(L, &slot);
  if (c.instance >= 0 && c.scene->instance_of_at(slot) != c.instance)
    throw Error("path '" + c.scene->PathOf(c.scene->IdAt(slot)) +
                "' belongs to another robot; only its own scripts (or a scene script) can set it");
  return p;
}

double FiniteArg(lua_State* L, int arg, const char* what) {
  const double value = ArgNumber(L, arg);
  if (!std::isfinite(value)) throw Error(std::string(what) + " is not a finite number");
  return value;
}

int GetPathLength(lua_State* L) {
  uint32_t slot = 0;
  lua_pushnumber(L, PathArg(L, &slot).curve->length());
  return 1;
}

int GetPathPose(lua_State* L) {
  uint32_t slot = 0;
  const PathRow& p = PathArg(L, &slot);
  const double s = FiniteArg(L, 2, "the arc length");
  const Pose X = Context(L).scene->world_pose_at(slot) * p.curve->PoseAt(s);
  const double v[7] = {X.p.x, X.p.y, X.p.z, X.q.x, X.q.y, X.q.z, X.q.w};
  PushNumberArray(L, v, 7);
  return 1;
}

int GetPathPosition(lua_State* L) {
  uint32_t slot = 0;
  lua_pushnumber(L, PathArg(L, &slot).position);
  return 1;
}

int SetPathPosition(lua_State* L) {
  PathRow& p = OwnPathArg(L);
  p.requested_position = p.curve->Normalize(FiniteArg(L, 2, "the position"));
  return 0;
}

int SetPathVelocity(lua_State* L) {
  PathRow& p = OwnPathArg(L);
  p.velocity = FiniteArg(L, 2, "the velocity");
  return 0;
}

// The conveyor at argument 1 (or the parent conveyor of the object there).
ConveyorRow& ConveyorArg(lua_State* L, uint32_t* slot) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  *slot = scene.SlotOf(id);
  ObjectType type;
  if (!scene.FindType(kConveyorTypeName, &type))
    throw Error("conveyors are not available in this world");
  if (scene.type_at(*slot) != type) {
    const int32_t parent = scene.parent_at(*slot);
    if (parent < 0 || scene.type_at(static_cast<uint32_t>(parent)) != type)
      throw Error("object " + scene.PathOf(id) + " is neither a conveyor nor a conveyor's child");
    *slot = static_cast<uint32_t>(parent);
  }
  return static_cast<Rows<ConveyorRow>&>(*scene.rows(type)).rows[scene.row_at(*slot)];
}

int GetConveyorSpeed(lua_State* L) {
  uint32_t slot = 0;
  lua_pushnumber(L, ConveyorArg(L, &slot).speed);
  return 1;
}

int SetConveyorSpeed(lua_State* L) {
  const LuaContext& c = Context(L);
  uint32_t slot = 0;
  ConveyorRow& row = ConveyorArg(L, &slot);
  if (c.instance >= 0 && c.scene->instance_of_at(slot) != c.instance)
    throw Error("conveyor '" + c.scene->PathOf(c.scene->IdAt(slot)) +
                "' belongs to another robot; only its own scripts (or a scene script) can set it");
  const double v = FiniteArg(L, 2, "the speed");
  if (std::abs(v) > kMaxCoordinate) throw Error("the speed is out of range (|v| > 1e6 m/s)");
  row.requested_speed = v;
  return 0;
}

}  // namespace

void RegisterConveyorApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"getConveyorSpeed", Guarded<GetConveyorSpeed, "sim.getConveyorSpeed">},
      {"setConveyorSpeed", Guarded<SetConveyorSpeed, "sim.setConveyorSpeed">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

void RegisterPathApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"getPathLength", Guarded<GetPathLength, "sim.getPathLength">},
      {"getPathPose", Guarded<GetPathPose, "sim.getPathPose">},
      {"getPathPosition", Guarded<GetPathPosition, "sim.getPathPosition">},
      {"setPathPosition", Guarded<SetPathPosition, "sim.setPathPosition">},
      {"setPathVelocity", Guarded<SetPathVelocity, "sim.setPathVelocity">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::paths
