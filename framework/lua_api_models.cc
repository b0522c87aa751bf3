// sim.* models: copying and removing robots at run time (paper §2.3;
// CoppeliaSim's sim.copyPasteObjects and sim.removeObjects on a model).
//
// The scene is read-only during the control phase and robots run in
// parallel, so a copy or a removal is queued (RobotRuntime::model_edits) and
// applied by the World between the control and the actuate phase (with a
// main script: in sim.handleActuation(), and after sysCall_step returns for
// what it queued later): robots in index order, then the scene's and the
// main script's, call order within each; all copies, then all removals
// (world_model_edits.cc). The handles of a copy are not known when the call
// returns: the copy announces itself from its own sysCall_init if others
// need to know (a message, a signal). Only whole robots (a model instance's
// root) are copied or removed.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

// The robot whose model root is `id`; throws naming the handle for a stale,
// unknown or null one, and for an object that is not a robot's root.
int CheckRobotRoot(const Scene& scene, ObjectId id) {
  scene.SlotOf(id, "robot");  // throws "robot handle 123 is stale: the object was removed"
  const int robot = scene.instance_of(id);
  if (robot < 0 || scene.instance(robot).root != id)
    throw Error("'" + scene.PathOf(id) + "' (handle " + std::to_string(id.ToInteger()) +
                ") is not a robot: only a model instance's root can be copied or removed at run "
                "time (sim.getObject(':') in a robot's script)");
  return robot;
}

// Queues `edit` for the caller's state, up to kMaxModelEditsPerStep a step.
void Queue(lua_State* L, const ModelEdit& edit) {
  std::vector<ModelEdit>& queued = Context(L).runtime->model_edits.get();
  if (queued.size() >= kMaxModelEditsPerStep)
    throw Error("more than " + std::to_string(kMaxModelEditsPerStep) +
                " robot copies and removals queued in one step by these scripts");
  queued.push_back(edit);
}

}  // namespace

void QueueSceneAddition(lua_State* L, std::function<void(Scene*)> add, uint64_t bytes,
                        const char* what) {
  ModelEdit edit;
  edit.kind = ModelEdit::Kind::kAdd;
  edit.add = std::move(add);
  Queue(L, edit);
  // Charged once queued (Queue may refuse), for the robot's lifetime.
  RobotRuntime& runtime = *Context(L).runtime;
  try {
    ChargeScriptData(L, bytes, what);
  } catch (...) {
    runtime.model_edits.pop_back();
    throw;
  }
  runtime.lifetime_bytes += bytes;
}

namespace {

// The optional pose argument {x, y, yaw} (m, m, rad) of sim.copyModel.
void ReadPose(lua_State* L, int arg, ModelEdit* edit) {
  if (lua_isnoneornil(L, arg)) return;
  ArgType(L, arg, LUA_TTABLE);
  double v[3];
  for (int i = 0; i < 3; ++i) {
    const int type = lua_rawgeti(L, arg, i + 1);
    const bool ok = type == LUA_TNUMBER;
    v[i] = ok ? lua_tonumber(L, -1) : 0;
    lua_pop(L, 1);
    if (!ok || !std::isfinite(v[i]))
      throw Error("bad argument #" + std::to_string(arg) +
                  " (pose {x, y, yaw} of three finite numbers expected)");
  }
  if (std::abs(v[0]) > kMaxCoordinate || std::abs(v[1]) > kMaxCoordinate) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the position (%g, %g) is beyond +-1e6 m, the largest coordinate a world may use",
                  v[0], v[1]);
    throw Error(text);
  }
  edit->has_pose = true;
  edit->x = v[0];
  edit->y = v[1];
  edit->yaw = v[2];
}

// sim.copyModel(robot [, {x, y, yaw}]): queues a copy of the robot whose
// model root is `robot`, placed at (x, y) heading yaw (default: the
// source's pose). Returns nothing: the copy exists from the end of the
// control phase (its sysCall_init runs then).
int CopyModel(lua_State* L) {
  const LuaContext& c = Context(L);
  ModelEdit edit;
  edit.root = CheckObject(L, 1);
  const int source = CheckRobotRoot(*c.scene, edit.root);
  ReadPose(L, 2, &edit);
  // The copy's objects count against the run's script memory from this
  // call (World::ApplyModelEdits hands the bytes to the copy's own account):
  // a script copying robots without end is stopped here, at its line, not
  // by the machine.
  RunScriptMemory* run = c.memory != nullptr ? c.memory->run() : nullptr;
  const ModelInstance& copied = c.scene->instance(source);
  if (run != nullptr) edit.charged = CopyChargeBytes(copied.objects.size());
  Queue(L, edit);
  if (edit.charged > 0 && !run->Take(edit.charged)) {
    c.runtime->model_edits.pop_back();
    throw Error("the copy of '" + copied.name + "' (" + std::to_string(copied.objects.size()) +
                " objects) would take the run's scripts past " +
                std::to_string(run->limit() >> 20) +
                " MiB (simulation.run_script_memory_mb; a copy counts " +
                std::to_string(kCopyBytesPerObject) + " bytes an object)");
  }
  return 0;
}

// sim.removeModel(robot): queues the removal of the robot whose model root
// is `robot` (its own scripts may remove it: sim.removeModel(sim.getObject(':'))).
int RemoveModel(lua_State* L) {
  const LuaContext& c = Context(L);
  ModelEdit edit;
  edit.kind = ModelEdit::Kind::kRemove;
  edit.root = CheckObject(L, 1);
  CheckRobotRoot(*c.scene, edit.root);
  Queue(L, edit);
  return 0;
}

// Queues a `kKind` edit for each robot handle of the array at argument 1
// (all checked first: nothing is queued if one is bad).
template <ModelEdit::Kind kKind>
int QueueEach(lua_State* L) {
  const LuaContext& c = Context(L);
  ArgType(L, 1, LUA_TTABLE);
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, 1));
  if (n > static_cast<lua_Integer>(kMaxModelEditsPerStep))
    throw Error("more than " + std::to_string(kMaxModelEditsPerStep) + " handles");
  std::vector<ModelEdit> edits(static_cast<size_t>(n));
  for (lua_Integer i = 1; i <= n; ++i) {
    const int type = lua_rawgeti(L, 1, i);
    const lua_Integer value = type == LUA_TNUMBER ? lua_tointeger(L, -1) : 0;
    lua_pop(L, 1);
    if (type != LUA_TNUMBER) throw Error("bad argument #1 (array of robot handles expected)");
    edits[i - 1].kind = kKind;
    edits[i - 1].root = ObjectId::FromInteger(value);
    CheckRobotRoot(*c.scene, edits[i - 1].root);
  }
  for (const ModelEdit& edit : edits) Queue(L, edit);
  return 0;
}

// sim.copyPasteObjects({robot, ...} [, options]): sim.copyModel of each,
// at the source's pose (CoppeliaSim's name; options must be nil or 0).
// Unlike CoppeliaSim it returns nothing: the copies' handles are not known
// before the end of the control phase.
int CopyPasteObjects(lua_State* L) {
  if (!lua_isnoneornil(L, 2) && !(lua_isinteger(L, 2) && lua_tointeger(L, 2) == 0))
    throw Error("bad argument #2 (options: only 0 is supported)");
  lua_settop(L, 1);
  return QueueEach<ModelEdit::Kind::kCopy>(L);
}

// sim.removeObjects({robot, ...}): sim.removeModel of each (CoppeliaSim's name).
int RemoveObjects(lua_State* L) {
  lua_settop(L, 1);
  return QueueEach<ModelEdit::Kind::kRemove>(L);
}

// sim.getRobots() -> the model-root handles of the robots not removed, in
// robot index order (as of the start of the phase).
int GetRobots(lua_State* L) {
  const LuaContext& c = Context(L);
  const auto instances = c.scene->instances();
  lua_createtable(L, static_cast<int>(instances.size()), 0);
  lua_Integer k = 0;
  for (const ModelInstance& instance : instances) {
    if (!instance.alive) continue;
    lua_pushinteger(L, instance.root.ToInteger());
    lua_rawseti(L, -2, ++k);
  }
  return 1;
}

}  // namespace

void RegisterModelsApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"copyModel", Guarded<CopyModel, "sim.copyModel">},
      {"removeModel", Guarded<RemoveModel, "sim.removeModel">},
      {"copyPasteObjects", Guarded<CopyPasteObjects, "sim.copyPasteObjects">},
      {"removeObjects", Guarded<RemoveObjects, "sim.removeObjects">},
      {"getRobots", Guarded<GetRobots, "sim.getRobots">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim
