// A module's own object type brings its Lua API area with it: a world whose
// registry holds the type has its sim.* functions, one without does not
// (lua_api.cc, PushRegisteredTypeFunction).
#include "framework/lua_api.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

struct CounterRow {
  int count = 0;
};

// sim.bumpCounter(h): adds one to the counter object's count and returns it.
int BumpCounter(lua_State* L) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  ObjectType type;
  if (!scene.IsValid(id) || !scene.FindType("counter", &type) || scene.type(id) != type)
    RaiseError(L, "sim.bumpCounter: not a counter");
  auto& rows = static_cast<Rows<CounterRow>&>(*scene.rows(type));
  lua_pushinteger(L, ++rows.rows[scene.row_at(scene.SlotOf(id))].count);
  return 1;
}

void RegisterCounterApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"bumpCounter", Guarded<BumpCounter, "sim.bumpCounter">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

std::shared_ptr<const ObjectTypeDescriptor> CounterType() {
  auto type = std::make_shared<ObjectTypeDescriptor>();
  type->name = "counter";
  type->description = "counts its bumps (test)";
  type->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<CounterRow>>();
  };
  type->register_lua = RegisterCounterApi;
  return type;
}

// One robot (a dummy root, named bot#0) with a counter and `code` on it.
std::vector<std::string> RunRobot(ModuleRegistry registry, const std::string& code) {
  WorldSettings settings;
  settings.physics = "null";
  settings.time_step = 0.1;
  World world(settings, registry);
  std::vector<std::string> log;
  world.set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  Scene& scene = world.scene();
  const ObjectId root = scene.AddDummy("bot#0", {}, {});
  ObjectType counter;
  if (scene.FindType("counter", &counter)) scene.AddObject(counter, "c", root, {}, nullptr);
  scene.MakeModelInstance(root, "bot", "bot#0");
  scene.AttachScript(root,
                     std::make_shared<const ScriptSource>(ScriptSource{"scripts/bot.lua", code}));
  world.Start();
  world.Step();
  world.Step();
  world.Stop();
  return log;
}

TEST(RegisteredTypeLuaTest, ARegisteredTypesFunctionsAreInTheWorldsSimTable) {
  ModuleRegistry registry = testing::NullRegistry();
  registry.RegisterObjectType(CounterType());
  const std::vector<std::string> log = RunRobot(registry, R"(
    function sysCall_actuation() print('count', sim.bumpCounter(sim.getObject('./c'))) end
  )");
  EXPECT_NE(std::find(log.begin(), log.end(), "[bot#0] count\t1"), log.end());
  EXPECT_NE(std::find(log.begin(), log.end(), "[bot#0] count\t2"), log.end());
}

TEST(RegisteredTypeLuaTest, WithoutTheTypeTheFunctionIsNotThere) {
  const std::vector<std::string> log = RunRobot(testing::NullRegistry(), R"(
    function sysCall_init() print('has', sim.bumpCounter ~= nil) end
  )");
  EXPECT_NE(std::find(log.begin(), log.end(), "[bot#0] has\tfalse"), log.end());
}

}  // namespace
}  // namespace swarmsim
