// sim.* planning (the Lua area of the planning_task type):
//   sim.planPath(task, goal [, time_limit]): asks for a plan from the robot's
//     pose now to `goal` ({x, y, yaw} planar, {x, y, z, qx, qy, qz, qw} se3,
//     world frame); computed in this step's actuate phase, robots in
//     parallel; its seed is drawn from the robot's random stream here.
//   sim.readPlan(task) -> status ('none', 'pending', 'solved', 'failed'),
//     reason ('solved', 'timeout', 'invalid goal: in collision', ...), the
//     plan's path object (its curve is the last solved plan), its length (m)
//   sim.getPlanStates(task) -> {{x, y, yaw}, ...} (se3: {x, y, z, qx, qy,
//     qz, qw}): the last solved plan every `resolution` m, headings included
//   sim.setPlanningTask(task, {space=, turning_radius=, resolution=,
//     time_limit=, bounds=, obstacles=}): adjusts the task's settings
// A script plans with its own robot's tasks only (a scene script with any).
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "framework/collections.h"
#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/paths/rows.h"
#include "modules/planning/rows.h"

namespace swarmsim::planning {

namespace {

PlanningTaskRow& TaskArg(lua_State* L, bool own) {
  const LuaContext& c = Context(L);
  Scene& scene = *c.scene;
  const ObjectId id = CheckObject(L, 1);
  const uint32_t slot = scene.SlotOf(id);
  ObjectType type;
  if (!scene.FindType(kTypeName, &type) || scene.type_at(slot) != type)
    throw Error("object " + scene.PathOf(id) + " is not a planning_task");
  if (own && c.instance >= 0 && scene.instance_of_at(slot) != c.instance)
    throw Error("planning task '" + scene.PathOf(id) +
                "' belongs to another robot; only its own scripts (or a scene script) can use it");
  return static_cast<Rows<PlanningTaskRow>&>(*scene.rows(type)).rows[scene.row_at(slot)];
}

// The numbers of the array at `arg` (raw reads: no metamethods).
std::vector<double> NumberArray(lua_State* L, int arg, const char* what) {
  ArgType(L, arg, LUA_TTABLE);
  std::vector<double> out;
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, arg));
  for (lua_Integer i = 1; i <= n; ++i) {
    const int type = lua_rawgeti(L, arg, i);
    const double v = lua_tonumber(L, -1);
    lua_pop(L, 1);
    if (type != LUA_TNUMBER || !std::isfinite(v))
      throw Error(std::string(what) + ": element " + std::to_string(i) + " is not a finite number");
    out.push_back(v);
  }
  return out;
}

Pose GoalArg(lua_State* L, int arg, Space space) {
  const std::vector<double> v = NumberArray(L, arg, "the goal");
  if (IsPlanar(space)) {
    if (v.size() != 3)
      throw Error("bad argument #2 (a goal {x, y, yaw} expected for a " +
                  std::string(SpaceName(space)) + " task, got " + std::to_string(v.size()) +
                  " numbers)");
    return {{v[0], v[1], 0}, Quat::FromYaw(v[2])};
  }
  if (v.size() != 7)
    throw Error("bad argument #2 (a goal {x, y, z, qx, qy, qz, qw} expected for an se3 task, got " +
                std::to_string(v.size()) + " numbers)");
  const Quat q{v[6], v[3], v[4], v[5]};
  if (!(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z > 1e-12))
    throw Error("bad argument #2 (the goal's quaternion is zero)");
  return {{v[0], v[1], v[2]}, q.Normalized()};
}

// A number for a message: "0.5", "inf", "-inf", "nan".
std::string NumberText(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream out;
  out << v;
  return out.str();
}

// As the world file's time_limit (objects.cc): at most an hour of planner
// iterations, so a script cannot ask for a plan that never ends.
constexpr double kMaxTimeLimit = 3600;

double TimeLimit(double value, const char* what) {
  if (!std::isfinite(value) || value <= 0 || value > kMaxTimeLimit)
    throw Error(std::string(what) + " must be a positive number of seconds, at most 3600 (got " +
                NumberText(value) + "): it is the planner's budget");
  return value;
}

int PlanPath(lua_State* L) {
  PlanningTaskRow& t = TaskArg(L, /*own=*/true);
  const Pose goal = GoalArg(L, 2, t.space);
  const double limit =
      lua_isnoneornil(L, 3) ? t.time_limit : TimeLimit(ArgNumber(L, 3), "the time limit");
  t.goal = goal;
  t.request_time_limit = limit;
  t.seed = Context(L).runtime->rng.NextU64();
  t.requested = true;
  t.status = PlanStatus::kPending;
  t.reason = "pending";
  return 0;
}

int ReadPlan(lua_State* L) {
  const PlanningTaskRow& t = TaskArg(L, /*own=*/false);
  static constexpr const char* kStatus[] = {"none", "pending", "solved", "failed"};
  lua_pushstring(L, kStatus[static_cast<int>(t.status)]);
  lua_pushstring(L, t.reason.c_str());
  Scene& scene = *Context(L).scene;
  double length = 0;
  if (scene.IsValid(t.path)) {
    lua_pushinteger(L, t.path.ToInteger());
    if (t.status != PlanStatus::kNone && !t.dense.empty())
      length = paths::PathRows(&scene)->rows[scene.row_at(t.path.index())].curve->length();
  } else {
    lua_pushnil(L);
  }
  lua_pushnumber(L, length);
  return 4;
}

int GetPlanStates(lua_State* L) {
  const PlanningTaskRow& t = TaskArg(L, /*own=*/false);
  const bool planar = IsPlanar(t.space);
  lua_createtable(L, static_cast<int>(t.dense.size()), 0);
  for (size_t i = 0; i < t.dense.size(); ++i) {
    const Pose& X = t.dense[i];
    if (planar) {
      const double v[3] = {X.p.x, X.p.y, X.q.Yaw()};
      PushNumberArray(L, v, 3);
    } else {
      const double v[7] = {X.p.x, X.p.y, X.p.z, X.q.x, X.q.y, X.q.z, X.q.w};
      PushNumberArray(L, v, 7);
    }
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  return 1;
}

int SetPlanningTask(lua_State* L) {
  PlanningTaskRow& t = TaskArg(L, /*own=*/true);
  ArgType(L, 2, LUA_TTABLE);
  PlanningTaskRow next = t;
  static const std::string kKeys[] = {"space",      "turning_radius", "resolution",
                                      "time_limit", "bounds",         "obstacles"};
  // Every key is known.
  lua_pushnil(L);
  while (lua_next(L, 2) != 0) {
    lua_pop(L, 1);
    const std::string key = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
    bool known = false;
    for (const std::string& k : kKeys) known = known || k == key;
    if (!known) {
      lua_pop(L, 1);
      throw Error("unknown setting '" + key +
                  "' (space, turning_radius, resolution, time_limit, bounds, obstacles)");
    }
  }
  const auto field = [&](const char* key) {
    lua_pushstring(L, key);
    return lua_rawget(L, 2);  // leaves the value on the stack
  };
  const auto number = [&](const char* key, double* out) {
    if (field(key) != LUA_TNIL) {
      const double v = lua_tonumber(L, -1);
      const bool ok = lua_type(L, -1) == LUA_TNUMBER;
      lua_pop(L, 1);
      if (!ok) throw Error(std::string(key) + " must be a number");
      *out = v;
      return true;
    }
    lua_pop(L, 1);
    return false;
  };
  if (field("space") != LUA_TNIL) {
    const std::string text = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
    lua_pop(L, 1);
    if (!ParseSpace(text, &next.space))
      throw Error("unknown state space '" + text + "' (se2, se3, dubins, reeds_shepp)");
  } else {
    lua_pop(L, 1);
  }
  double v = 0;
  if (number("turning_radius", &v)) {
    if (!(v > 0 && std::isfinite(v))) throw Error("turning_radius must be a positive number");
    next.turning_radius = v;
  }
  if (number("resolution", &v)) {
    if (!(v >= 1e-4 && std::isfinite(v)))
      throw Error("resolution must be a number of metres from 0.0001 (got " + NumberText(v) + ")");
    next.resolution = v;
  }
  if (number("time_limit", &v)) next.time_limit = TimeLimit(v, "time_limit");
  if (field("obstacles") != LUA_TNIL) {
    const std::string text = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
    lua_pop(L, 1);
    if (ParseEntity(text).kind == EntitySpec::kPath &&
        Context(L).scene->FindObject(text, CheckObject(L, 1)).IsNull())
      throw Error("obstacles '" + text +
                  "' is neither 'environment', 'everything_else' nor an object path that matches");
    next.obstacles = text;
  } else {
    lua_pop(L, 1);
  }
  const bool bounds_given = field("bounds") != LUA_TNIL;
  if (bounds_given) {
    const int index = lua_gettop(L);
    const std::vector<double> b = NumberArray(L, index, "bounds");
    lua_pop(L, 1);
    const size_t n = IsPlanar(next.space) ? 4 : 6;
    if (b.size() != n)
      throw Error(n == 4 ? "bounds must be {xmin, ymin, xmax, ymax}"
                         : "bounds must be {xmin, ymin, zmin, xmax, ymax, zmax}");
    next.has_bounds = true;
    next.lo = n == 4 ? Vec3{b[0], b[1], 0} : Vec3{b[0], b[1], b[2]};
    next.hi = n == 4 ? Vec3{b[2], b[3], 0} : Vec3{b[3], b[4], b[5]};
    if (!(next.lo.x < next.hi.x && next.lo.y < next.hi.y && (n == 4 || next.lo.z < next.hi.z)))
      throw Error("bounds: each minimum must be below its maximum");
  } else {
    lua_pop(L, 1);
  }
  if (IsPlanar(next.space) != IsPlanar(t.space) && next.has_bounds && !bounds_given)
    throw Error("the task's bounds are " + std::string(IsPlanar(t.space) ? "planar" : "3D") +
                ": give new bounds with a space of the other kind");
  t = std::move(next);
  return 0;
}

}  // namespace

void RegisterPlanningApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"planPath", Guarded<PlanPath, "sim.planPath">},
      {"readPlan", Guarded<ReadPlan, "sim.readPlan">},
      {"getPlanStates", Guarded<GetPlanStates, "sim.getPlanStates">},
      {"setPlanningTask", Guarded<SetPlanningTask, "sim.setPlanningTask">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::planning
