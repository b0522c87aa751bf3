// sim.* objects: lookup by path, names, the tree, poses.
//
// Poses are read from the scene as it was at the start of the control
// phase (nothing moves objects during it), so any robot may read any object.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

// sim.getObject(path [, {noError = true}]) -> handle (or -1 with noError).
// Paths as Scene::FindObject: '.', './a/b', ':/a', '/a/b', 'name[k]'.
int GetObject(lua_State* L) {
  const LuaContext& c = Context(L);
  size_t length = 0;
  const char* path = ArgString(L, 1, &length);
  bool no_error = false;
  if (lua_istable(L, 2)) {
    lua_pushliteral(L, "noError");  // raw: no metamethod may raise here
    lua_rawget(L, 2);
    no_error = lua_toboolean(L, -1);
    lua_pop(L, 1);
  } else if (!lua_isnoneornil(L, 2)) {
    throw Error(std::string("bad argument #2 (table of options expected, got ") +
                luaL_typename(L, 2) + ")");
  }
  // A malformed path throws even with noError: it is a mistake in the script.
  const ObjectId id = c.scene->FindObject({path, length}, c.script_object);
  if (!id.IsNull()) {
    lua_pushinteger(L, id.ToInteger());
    return 1;
  }
  if (no_error) {
    lua_pushinteger(L, -1);
    return 1;
  }
  // Not found: what the path could have meant (the tree is walked again).
  const std::string_view wanted(path, length);
  throw Error("no object at path '" + std::string(wanted) + "' (looked up from " +
              c.scene->PathOf(c.script_object) + ")" +
              c.scene->ExplainMissingPath(wanted, c.script_object));
}

// Pose of the object at argument 1 in the frame of the object at argument 2
// (world if absent or sim.handle_world).
Pose RelativePose(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  const Pose& X_WO = scene.world_pose_at(scene.SlotOf(CheckObject(L, 1)));
  const ObjectId relative_to = OptRelativeTo(L, 2);
  if (relative_to.IsNull()) return X_WO;
  const Pose& X_WR = scene.world_pose_at(scene.SlotOf(relative_to, "relative-to object"));
  return X_WR.Inverse() * X_WO;
}

// sim.getObjectPose(h [, relTo]) -> {x, y, z, qx, qy, qz, qw} (CoppeliaSim order).
int GetObjectPose(lua_State* L) {
  const Pose X = RelativePose(L);
  const double v[7] = {X.p.x, X.p.y, X.p.z, X.q.x, X.q.y, X.q.z, X.q.w};
  PushNumberArray(L, v, 7);
  return 1;
}

// sim.getObjectPosition(h [, relTo]) -> {x, y, z}.
int GetObjectPosition(lua_State* L) {
  const Pose X = RelativePose(L);
  const double v[3] = {X.p.x, X.p.y, X.p.z};
  PushNumberArray(L, v, 3);
  return 1;
}

// sim.getObjectOrientation(h [, relTo]) -> {roll, pitch, yaw}, radians.
// Unlike CoppeliaSim's Euler angles, these are extrinsic roll (x), pitch (y),
// yaw (z) with R = Rz(yaw) Ry(pitch) Rx(roll), as Quat::RollPitchYaw; for a
// robot on the floor, yaw is its heading.
int GetObjectOrientation(lua_State* L) {
  const Vec3 rpy = RelativePose(L).q.RollPitchYaw();
  const double v[3] = {rpy.x, rpy.y, rpy.z};
  PushNumberArray(L, v, 3);
  return 1;
}

// sim.getObjectName(h) -> name.
int GetObjectName(lua_State* L) {
  const std::string& name = Context(L).scene->name(CheckObject(L, 1));
  lua_pushlstring(L, name.data(), name.size());
  return 1;
}

// sim.getObjectParent(h) -> parent handle, or -1 for a root.
int GetObjectParent(lua_State* L) {
  const ObjectId parent = Context(L).scene->parent(CheckObject(L, 1));
  lua_pushinteger(L, parent.IsNull() ? -1 : parent.ToInteger());
  return 1;
}

// Reads a number array of length n at `arg`.
void CheckNumbers(lua_State* L, int arg, double* out, int n) {
  ArgType(L, arg, LUA_TTABLE);
  for (int i = 0; i < n; ++i) {
    lua_rawgeti(L, arg, i + 1);
    int ok = 0;
    out[i] = lua_tonumberx(L, -1, &ok);
    lua_pop(L, 1);
    if (!ok || !std::isfinite(out[i]))
      throw Error("expected a table of " + std::to_string(n) + " finite numbers");
  }
}

// What a sim.setObject* call sets.
enum class PoseArgument { kPose, kPosition, kOrientation };

// sim.setObjectPose(h, {x, y, z, qx, qy, qz, qw} [, relTo]),
// sim.setObjectPosition(h, {x, y, z} [, relTo]) and
// sim.setObjectOrientation(h, {roll, pitch, yaw} [, relTo]) (radians, as
// sim.getObjectOrientation gives them; the older argument order (h, relTo,
// values) works too). The move is queued and applied after the control
// phase in handle order, like writes to other robots, so every script reads
// the poses of the start of the phase.
int SetObjectPoseOrPart(lua_State* L, PoseArgument what) {
  const bool position_only = what == PoseArgument::kPosition;
  const LuaContext& c = Context(L);
  const ObjectId id = CheckObject(L, 1);
  const uint32_t slot = c.scene->SlotOf(id);
  const bool new_order = lua_istable(L, 2);
  const int values_arg = new_order ? 2 : 3, relative_arg = new_order ? 3 : 2;
  double v[7];
  CheckNumbers(L, values_arg, v, what == PoseArgument::kPose ? 7 : 3);
  const ObjectId relative_to = OptRelativeTo(L, relative_arg);
  const Pose X_WR =
      relative_to.IsNull()
          ? Pose{}
          : c.scene->world_pose_at(c.scene->SlotOf(relative_to, "relative-to object"));
  Pose X_WO = c.scene->world_pose_at(slot);
  if (position_only) {
    X_WO.p = X_WR * Vec3{v[0], v[1], v[2]};
  } else if (what == PoseArgument::kOrientation) {
    X_WO.q = (X_WR.q * Quat::FromRollPitchYaw(v[0], v[1], v[2])).Normalized();
  } else {
    // {0, 0, 0, 1e300} is a rotation too (its squared norm overflows);
    // {0, 0, 0, 0} is none.
    const double largest =
        std::max({std::abs(v[3]), std::abs(v[4]), std::abs(v[5]), std::abs(v[6])});
    if (largest == 0)
      throw Error("the quaternion {qx, qy, qz, qw} is {0, 0, 0, 0}, which is no rotation");
    // Scaled only where the squared norm would overflow or vanish: others
    // are normalised as they always were (the same bits).
    const double scale = largest > 1e150 || largest < 1e-150 ? largest : 1.0;
    const Quat q = Quat{v[6] / scale, v[3] / scale, v[4] / scale, v[5] / scale}.Normalized();
    X_WO = X_WR * Pose{{v[0], v[1], v[2]}, q};
  }
  // Within what a world file may use (the engines cannot take much more).
  if (!WithinWorld(X_WO.p)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the position (%g, %g, %g) is beyond +-1e6 m, the largest coordinate a world "
                  "may use",
                  X_WO.p.x, X_WO.p.y, X_WO.p.z);
    throw Error(text);
  }
  DeferredWrite w{id, DeferredWrite::Kind::kObjectPose, 0};
  w.pose = X_WO;
  PushDeferredWrite(L, w);
  return 0;
}
int SetObjectPose(lua_State* L) { return SetObjectPoseOrPart(L, PoseArgument::kPose); }
int SetObjectPosition(lua_State* L) { return SetObjectPoseOrPart(L, PoseArgument::kPosition); }
int SetObjectOrientation(lua_State* L) {
  return SetObjectPoseOrPart(L, PoseArgument::kOrientation);
}

// sim.getObjectSizeFactor(h) -> the object's accumulated scale (1 unless it
// or an ancestor was placed scaled or rescaled), as of the start of the phase.
int GetObjectSizeFactor(lua_State* L) {
  const LuaContext& c = Context(L);
  lua_pushnumber(L, c.scene->size_factor(CheckObject(L, 1)));
  return 1;
}

// sim.setObjectSizeFactor(h, f): rescales h's subtree about h so that h's
// size factor becomes f (Scene::ScaleSubtree; worlds/README.md lists what
// scales). Queued and applied after the control phase in handle order, like
// sim.setObjectPose; the dynamics backend rebuilds at the next physics step.
// A robot's scripts may rescale only their own robot's objects.
int SetObjectSizeFactor(lua_State* L) {
  const LuaContext& c = Context(L);
  const ObjectId id = CheckObject(L, 1);
  c.scene->SlotOf(id);
  const double f = ArgNumber(L, 2);
  if (!(f >= 1e-3 && f <= 1e3))  // (NaN fails too)
    throw Error("the size factor must be a number from 0.001 to 1000");
  if (c.instance >= 0 && c.scene->instance_of(id) != c.instance)
    throw Error("object '" + c.scene->PathOf(id) +
                "' belongs to another robot or the scene; a robot's scripts can rescale only "
                "their own robot");
  PushDeferredWrite(L, {id, DeferredWrite::Kind::kSizeFactor, f});
  return 0;
}

}  // namespace

void RegisterObjectsApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"getObject", Guarded<GetObject, "sim.getObject">},
      {"getObjectPose", Guarded<GetObjectPose, "sim.getObjectPose">},
      {"getObjectPosition", Guarded<GetObjectPosition, "sim.getObjectPosition">},
      {"getObjectOrientation", Guarded<GetObjectOrientation, "sim.getObjectOrientation">},
      {"getObjectName", Guarded<GetObjectName, "sim.getObjectName">},
      {"getObjectParent", Guarded<GetObjectParent, "sim.getObjectParent">},
      {"setObjectPose", Guarded<SetObjectPose, "sim.setObjectPose">},
      {"setObjectPosition", Guarded<SetObjectPosition, "sim.setObjectPosition">},
      {"setObjectOrientation", Guarded<SetObjectOrientation, "sim.setObjectOrientation">},
      {"getObjectSizeFactor", Guarded<GetObjectSizeFactor, "sim.getObjectSizeFactor">},
      {"setObjectSizeFactor", Guarded<SetObjectSizeFactor, "sim.setObjectSizeFactor">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim
