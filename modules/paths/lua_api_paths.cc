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
//   sim.createPath(points [, options]): a new path through points
//     {{x, y, z}, ...} (m, at least 2, finite, no two consecutive equal);
//     options {name = 'path', parent = h, closed = false, interpolation =
//     'linear'|'smooth', velocity = 0}. It is made when the step's copies and
//     removals of robots are (after the control phase, robots in index
//     order), so it exists the same for any thread count: from the next
//     step, sim.getObject finds it. A robot's script makes it under its own
//     object (or `parent`, one of its own); a scene script at the root (or
//     under `parent`).
// Conveyors (the conveyor type's area):
//   sim.getConveyorSpeed(h) -> m/s, the belt's speed as of the step's start
//   sim.setConveyorSpeed(h, v): m/s along its points (negative: backwards),
//     applied in the actuate phase (so every robot reads the same speed in
//     a step); only the conveyor's own robot's scripts (or a scene script)
//     may set it
// `h` is a conveyor or one of its children (a belt segment).
#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/suggest.h"
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

// Field `key` of the table at `arg` pushed on the stack (raw: no metamethods).
int RawField(lua_State* L, int arg, const char* key) {
  lua_pushstring(L, key);
  return lua_rawget(L, arg);
}

// The shortest segment a path may have.
constexpr double kMinSegment = 1e-9;  // m

int CreatePath(lua_State* L) {
  const LuaContext& c = Context(L);
  Scene& scene = *c.scene;
  ArgType(L, 1, LUA_TTABLE);
  // The points.
  std::vector<Vec3> points;
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, 1));
  if (n < 2) throw Error("bad argument #1 (at least 2 points {x, y, z} expected)");
  if (n > 100000) throw Error("bad argument #1 (more than 100000 points)");
  for (lua_Integer i = 1; i <= n; ++i) {
    if (lua_rawgeti(L, 1, i) != LUA_TTABLE)
      throw Error("bad argument #1 (point " + std::to_string(i) + " is not a table {x, y, z})");
    double v[3];
    for (int k = 0; k < 3; ++k) {
      const bool ok = lua_rawgeti(L, -1, k + 1) == LUA_TNUMBER;
      v[k] = ok ? lua_tonumber(L, -1) : NAN;
      lua_pop(L, 1);
      if (!ok || !std::isfinite(v[k]) || std::abs(v[k]) > kMaxCoordinate)
        throw Error("bad argument #1 (point " + std::to_string(i) +
                    " needs three finite numbers of metres {x, y, z})");
    }
    lua_pop(L, 1);
    points.push_back({v[0], v[1], v[2]});
    // Not only a repeated point: 1e-300 m from the last gave a path of
    // length 0 whose poses were NaN.
    if (points.size() > 1 && (points.back() - points[points.size() - 2]).Norm() < kMinSegment)
      throw Error("bad argument #1 (point " + std::to_string(i) +
                  (points.back() == points[points.size() - 2]
                       ? std::string(" repeats the one before")
                       : " is less than 1e-9 m from the one before") +
                  ": a path segment must have a length)");
  }
  // The options.
  std::string name = "path";
  ObjectId parent = c.instance >= 0 ? c.script_object : ObjectId{};
  bool closed = false;
  Interpolation interpolation = Interpolation::kLinear;
  double velocity = 0;
  if (!lua_isnoneornil(L, 2)) {
    ArgType(L, 2, LUA_TTABLE);
    // An option misspelt was dropped without a word ({velocty = 0.5}: a
    // path that never moved).
    static const std::string kOptions[] = {"name", "parent", "closed", "interpolation", "velocity"};
    lua_pushnil(L);
    while (lua_next(L, 2) != 0) {
      lua_pop(L, 1);  // the value; the key stays for lua_next
      const std::string key = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
      if (std::find(std::begin(kOptions), std::end(kOptions), key) == std::end(kOptions))
        throw Error("bad argument #2 (" +
                    (key.empty() ? std::string("options are named: a key that is not a string")
                                 : "no option '" + key + "'" + Suggest(key, kOptions)) +
                    ")");
    }
    if (RawField(L, 2, "name") != LUA_TNIL) {
      if (!lua_isstring(L, -1)) throw Error("bad argument #2 (options.name: a string expected)");
      name = lua_tostring(L, -1);
      if (name.empty() || name.find('/') != std::string::npos)
        throw Error("bad argument #2 (options.name: a name without '/' expected)");
    }
    lua_pop(L, 1);
    if (RawField(L, 2, "parent") != LUA_TNIL) {
      if (!lua_isinteger(L, -1)) throw Error("bad argument #2 (options.parent: a handle expected)");
      parent = ObjectId::FromInteger(lua_tointeger(L, -1));
      scene.SlotOf(parent, "options.parent");
    }
    lua_pop(L, 1);
    if (RawField(L, 2, "closed") != LUA_TNIL) closed = lua_toboolean(L, -1) != 0;
    lua_pop(L, 1);
    if (RawField(L, 2, "interpolation") != LUA_TNIL) {
      const std::string text = lua_isstring(L, -1) ? lua_tostring(L, -1) : "";
      if (text == "smooth")
        interpolation = Interpolation::kSmooth;
      else if (text != "linear")
        throw Error("bad argument #2 (options.interpolation: 'linear' or 'smooth' expected)");
    }
    lua_pop(L, 1);
    if (RawField(L, 2, "velocity") != LUA_TNIL) {
      velocity = lua_isnumber(L, -1) ? lua_tonumber(L, -1) : NAN;
      if (!std::isfinite(velocity))
        throw Error("bad argument #2 (options.velocity: a finite number expected)");
    }
    lua_pop(L, 1);
  }
  if (closed && (points.back() - points.front()).Norm() < kMinSegment)
    throw Error(
        "bad argument #1 (the last point repeats the first: a closed path already joins "
        "them)");
  if (c.instance >= 0 && (parent.IsNull() || scene.instance_of(parent) != c.instance))
    throw Error("a robot's script makes paths under its own objects only");
  PathRow row;
  row.curve = std::make_shared<const PathCurve>(std::move(points), interpolation, closed);
  row.velocity = velocity;
  // Charged to the robot for its lifetime: the path lives as long as it.
  const uint64_t bytes =
      kSceneObjectBytes + sizeof(PathCurve) + row.curve->HeldBytes() + 2 * name.size();
  QueueSceneAddition(
      L,
      [row = std::move(row), name, parent](Scene* scene) {
        ObjectType type;
        if (!scene->FindType(kTypeName, &type)) return;
        if (!parent.IsNull() && !scene->IsValid(parent)) return;  // removed meanwhile
        scene->AddObject(type, name, parent, Pose{}, &row);
      },
      bytes, "the path");
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
      {"createPath", Guarded<CreatePath, "sim.createPath">},
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
