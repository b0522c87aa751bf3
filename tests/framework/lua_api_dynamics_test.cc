// sim.* dynamics (framework/lua_api_dynamics.cc): the hybrid switch between
// dynamic and kinematic shapes, queued until the control phase ends so
// every robot sees the same flags, and joint forces for force-mode joints.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;

// A world with null modules whose script output lands in `log`; robots are
// a root dummy with a `body` shape (carrying the script) and a `motor`
// joint; `crate` is a static shape outside any robot.
class DynamicsWorld {
 public:
  explicit DynamicsWorld(int threads = 1) : registry_(testing::NullRegistry()) {
    WorldSettings settings;
    settings.physics = "null";
    settings.time_step = 0.1;
    settings.threads = threads;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
    crate = scene().AddShape("crate", {}, {}, {});
  }
  Scene& scene() { return world_->scene(); }
  World& world() { return *world_; }
  ObjectId AddRobot(const std::string& name, const std::string& code) {
    const ObjectId root = scene().AddDummy(name, {}, {});
    const ObjectId body = scene().AddShape("body", root, {}, {});
    scene().AddJoint("motor", body, {}, {});
    scene().MakeModelInstance(root, "bot", name);
    scene().AttachScript(
        body, std::make_shared<const ScriptSource>(ScriptSource{"scripts/robot.lua", code}));
    return root;
  }
  std::string Step() {
    return ErrorOf([&] { world_->Step(); });
  }
  std::vector<std::string> log;
  ObjectId crate;

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
};

TEST(LuaApiDynamicsTest, SetObjectDynamicTakesEffectAfterThePhase) {
  DynamicsWorld w;
  w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local crate = sim.getObject('/crate')
      print('before', sim.isObjectDynamic(crate))
      if sim.getSimulationTime() == 0 then sim.setObjectDynamic(crate, true) end
      print('after', sim.isObjectDynamic(crate))
    end
  )");
  EXPECT_EQ(w.Step(), "");
  EXPECT_TRUE(w.scene().shape(w.crate).dynamic);  // applied when the phase ended
  EXPECT_EQ(w.Step(), "");
  const std::vector<std::string> expected = {"[bot#0] before\tfalse", "[bot#0] after\tfalse",
                                             "[bot#0] before\ttrue", "[bot#0] after\ttrue"};
  EXPECT_EQ(w.log, expected);
}

// Writes to one shape in one step apply in robot order: the highest robot
// index wins, whatever the thread count.
TEST(LuaApiDynamicsTest, ConflictingSwitchesResolveInRobotOrderAtAnyThreadCount) {
  for (int threads : {1, 2, 4}) {
    for (bool last : {false, true}) {
      DynamicsWorld w(threads);
      for (int r = 0; r < 8; ++r) {
        const bool value = r == 7 ? last : !last;
        w.AddRobot("bot#" + std::to_string(r),
                   std::string("function sysCall_actuation() sim.setObjectDynamic("
                               "sim.getObject('/crate'), ") +
                       (value ? "true" : "false") + ") end");
      }
      EXPECT_EQ(w.Step(), "");
      EXPECT_EQ(w.scene().shape(w.crate).dynamic, last) << threads << " threads";
    }
  }
}

TEST(LuaApiDynamicsTest, OnlyShapesSwitchAndTheFlagMustBeABoolean) {
  const std::pair<std::string, std::string> cases[] = {
      {"sim.setObjectDynamic(sim.getObject(':/body/motor'), true)",
       "sim.setObjectDynamic: object 'motor' is a joint, not a shape"},
      {"sim.setObjectDynamic(sim.getObject(':/body'), 1)",
       "sim.setObjectDynamic: bad argument #2 (boolean expected, got number)"},
      {"sim.isObjectDynamic(sim.getObject(':'))",
       "sim.isObjectDynamic: object 'bot#0' is a dummy, not a shape"},
  };
  for (const auto& [call, message] : cases) {
    DynamicsWorld w;
    w.AddRobot("bot#0", "function sysCall_actuation()\n  " + call + "\nend");
    EXPECT_CONTAINS(w.Step(), "bot#0: scripts/robot.lua:2: " + message);
  }
}

TEST(LuaApiDynamicsTest, ARobotSetsTheForceOfItsOwnJointsOnly) {
  DynamicsWorld w;
  w.AddRobot("bot#0",
             "function sysCall_actuation() sim.setJointTargetForce("
             "sim.getObject(':/body/motor'), -2.5) end");
  EXPECT_EQ(w.Step(), "");
  EXPECT_EQ(w.scene().joint(w.scene().FindObject("/bot#0/body/motor")).target_force, -2.5);

  DynamicsWorld other;
  other.AddRobot("bot#0", "");
  other.AddRobot("bot#1",
                 "function sysCall_actuation()\n  sim.setJointTargetForce("
                 "sim.getObject('/bot#0/body/motor'), 1)\nend");
  EXPECT_CONTAINS(other.Step(),
                  "bot#1: scripts/robot.lua:2: sim.setJointTargetForce: joint "
                  "'/bot#0/body/motor' belongs to another robot; only its own scripts can set "
                  "its force");
  DynamicsWorld nan;
  nan.AddRobot("bot#0",
               "function sysCall_actuation()\n  sim.setJointTargetForce("
               "sim.getObject(':/body/motor'), 0/0)\nend");
  EXPECT_CONTAINS(nan.Step(), "sim.setJointTargetForce: the force is not a finite number");
  // 1e300 stopped ODE on an internal assertion, naming no script.
  DynamicsWorld huge;
  huge.AddRobot("bot#0",
                "function sysCall_actuation()\n  sim.setJointTargetForce("
                "sim.getObject(':/body/motor'), 1e300)\nend");
  EXPECT_CONTAINS(huge.Step(),
                  "scripts/robot.lua:2: sim.setJointTargetForce: the force 1e+300 is beyond "
                  "+-1e15 (N or N m)");
}

// A scene script (outside any robot) may set any joint's force.
TEST(LuaApiDynamicsTest, ASceneScriptSetsAnyJointsForce) {
  DynamicsWorld w;
  w.AddRobot("bot#0", "");
  w.scene().AttachScript(w.crate, std::make_shared<const ScriptSource>(ScriptSource{
                                      "scripts/scene.lua",
                                      "function sysCall_actuation() sim.setJointTargetForce("
                                      "sim.getObject('/bot#0/body/motor'), 4) end"}));
  EXPECT_EQ(w.Step(), "");
  EXPECT_EQ(w.scene().joint(w.scene().FindObject("/bot#0/body/motor")).target_force, 4);
}

}  // namespace
}  // namespace swarmsim
