// Copies and removals of robots at run time (sim.copyModel, sim.removeModel,
// lua_api_models.cc, applied by world_model_edits.cc).
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

std::shared_ptr<const ScriptSource> Source(std::string code) {
  return std::make_shared<const ScriptSource>(ScriptSource{"scripts/bot.lua", std::move(code)});
}

// A world with null modules whose script output lands in `log`; robots are
// a root dummy (the model root, named like the robot) carrying a `body`
// shape with the script.
class ModelWorld {
 public:
  explicit ModelWorld(int threads = 1) : registry_(testing::NullRegistry()) {
    WorldSettings settings;
    settings.physics = "null";
    settings.time_step = 0.1;
    settings.threads = threads;
    settings.seed = 3;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
  }
  World& world() { return *world_; }
  Scene& scene() { return world_->scene(); }
  ObjectId AddRobot(const std::string& code) {
    const std::string name = "bot#" + std::to_string(scene().instances().size());
    const ObjectId root = scene().AddDummy(name, {}, {{next_x_, 0, 0}, {}});
    next_x_ += 1;
    const ObjectId body = scene().AddShape("body", root, {}, {});
    scene().MakeModelInstance(root, "bot", name);
    if (!code.empty()) scene().AttachScript(body, Source(code));
    return root;
  }
  bool Logged(const std::string& line) const {
    return std::find(log.begin(), log.end(), line) != log.end();
  }
  std::vector<std::string> log;

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
  double next_x_ = 0;
};

using testing::ErrorOf;

// Robot 0 copies itself once, at step 0, to (2, 1) heading 0.5 rad.
const char kCopyOnce[] = R"(
  local me = sim.getObject(':')
  function sysCall_init()
    local p = sim.getObjectPosition(me)
    print('init', sim.getRobotName(), sim.getParam('speed'), p[1], p[2], sim.random())
  end
  function sysCall_actuation()
    print('act', sim.getSimulationTime())
    if sim.getRobotIndex() == 0 and sim.getSimulationTime() == 0 then
      sim.copyModel(me, {2, 1, 0.5})
    end
  end
)";

TEST(WorldModelEditsTest, ACopyRunsInitThenActuationWithTheSourcesParameters) {
  ModelWorld w;
  w.AddRobot(kCopyOnce);
  w.world().SetInstanceParameters(
      0, std::make_shared<const ParameterSet>(ParameterSet{{"speed", 3.0}}));
  w.world().Start();
  w.world().Step();
  ASSERT_EQ(w.world().robot_count(), 2);
  EXPECT_EQ(w.scene().instance(1).name, "bot#1");
  EXPECT_EQ(w.scene().name(w.scene().instance(1).root), "bot#1");
  const Pose X_WR = w.scene().world_pose(w.scene().instance(1).root);
  EXPECT_NEAR(X_WR.q.Yaw(), 0.5, 1e-12);
  w.world().Step();
  w.world().Stop();
  // bot#1 inits after step 0's control phase, before its first actuation.
  std::vector<std::string> robot1;
  for (const std::string& line : w.log)
    if (line.starts_with("[bot#1]")) robot1.push_back(line.substr(0, line.rfind('\t')));
  const std::vector<std::string> expected = {"[bot#1] init\tbot#1\t3\t2.0\t1.0", "[bot#1] act"};
  EXPECT_EQ(robot1, expected);
  EXPECT_TRUE(w.Logged("[bot#0] act\t0.1"));
  EXPECT_TRUE(w.Logged("[bot#1] act\t0.1"));
  // Its own random stream: its first draw is not its source's.
  const auto draw = [&](const std::string& prefix) {
    for (const std::string& line : w.log)
      if (line.starts_with(prefix + " init")) return line.substr(line.rfind('\t') + 1);
    return std::string();
  };
  EXPECT_NE(draw("[bot#0]"), "");
  EXPECT_NE(draw("[bot#0]"), draw("[bot#1]"));
}

TEST(WorldModelEditsTest, ARemovedRobotCleansUpItsHandleIsStaleAndItIsNotHashed) {
  // Robot 1 draws `draws` numbers then removes itself at step 1; robot 0
  // holds its root and reads its position at step 3.
  const auto run = [](int draws, bool read_removed) {
    ModelWorld w;
    w.AddRobot(std::string("local read = ") + (read_removed ? "true" : "false") + R"(
      local other = sim.getObject('/bot#1')
      function sysCall_actuation()
        if read and sim.getSimulationTime() > 0.25 then sim.getObjectPosition(other) end
      end
    )");
    w.AddRobot("local draws = " + std::to_string(draws) + R"(
      function sysCall_actuation()
        if sim.getSimulationTime() > 0.05 then
          for i = 1, draws do sim.random() end
          sim.removeModel(sim.getObject(':'))
        end
      end
      function sysCall_cleanup() print('cleanup', sim.getObjectName(sim.getObject('.'))) end
    )");
    w.world().Start();
    w.world().Step();
    w.world().Step();
    EXPECT_EQ(w.log, std::vector<std::string>{"[bot#1] cleanup\tbody"});
    EXPECT_FALSE(w.scene().instance(1).alive);
    EXPECT_EQ(w.world().robot_count(), 2);
    EXPECT_EQ(w.world().live_robot_count(), 1);
    w.world().Step();
    const std::string error = ErrorOf([&] { w.world().Step(); });
    return std::pair(w.world().StateHash(), error);
  };
  const auto [hash1, none1] = run(1, false);
  const auto [hash5, none5] = run(5, false);
  EXPECT_EQ(none1, "");
  EXPECT_EQ(hash1, hash5);  // its random stream left with it
  const std::string error = run(1, true).second;
  EXPECT_CONTAINS(error, "sim.getObjectPosition");
  EXPECT_CONTAINS(error, "is stale: the object was removed");
}

// A direct message to a removed robot's script: its handle is stale (it
// said the object "carries no script").
TEST(WorldModelEditsTest, ADirectMessageToARemovedRobotNamesTheHandleStale) {
  ModelWorld w;
  w.AddRobot(R"(
    local other = sim.getObject('/bot#1/body')
    function sysCall_actuation()
      if sim.getSimulationTime() > 0.25 then sim.sendDirectMessage(other, 'hello') end
    end
  )");
  w.AddRobot(R"(
    function sysCall_actuation()
      if sim.getSimulationTime() > 0.05 then sim.removeModel(sim.getObject(':')) end
    end
  )");
  w.world().Start();
  std::string error;
  for (int k = 0; k < 5 && error.empty(); ++k) error = ErrorOf([&] { w.world().Step(); });
  EXPECT_CONTAINS(error, "sim.sendDirectMessage");
  EXPECT_CONTAINS(error, "is stale: the object was removed");
}

TEST(WorldModelEditsTest, CopyAndRemoveOfTheSameRobotInOneStepCopiesThenRemoves) {
  ModelWorld w;
  w.AddRobot(R"(
    function sysCall_init() print('init') end
    function sysCall_actuation()
      if sim.getRobotIndex() == 0 then
        sim.copyPasteObjects({sim.getObject(':')}, 0)
        sim.removeObjects({sim.getObject(':'), sim.getObject(':')})
      end
    end
  )");
  w.world().Start();
  w.world().Step();
  EXPECT_EQ(w.world().robot_count(), 2);
  EXPECT_EQ(w.world().live_robot_count(), 1);
  EXPECT_TRUE(w.scene().instance(1).alive);
  w.world().Step();
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#0] init", "[bot#1] init"}));
}

TEST(WorldModelEditsTest, ManyCopiesInOneStepWork) {
  ModelWorld w;
  w.AddRobot(R"(
    function sysCall_actuation()
      if sim.getRobotIndex() == 0 and sim.getSimulationTime() == 0 then
        for i = 1, 1000 do sim.copyModel(sim.getObject(':'), {i, 0, 0}) end
      end
    end
  )");
  w.world().Step();
  w.world().Step();
  EXPECT_EQ(w.world().live_robot_count(), 1001);
  EXPECT_EQ(w.scene().instance(1000).name, "bot#1000");
}

// A swarm where robots fail at random and are replaced by copies of a live
// robot (from the robots' own scripts, so that they run in parallel).
uint64_t RespawnHash(int threads, std::vector<std::string>* log) {
  ModelWorld w(threads);
  const char kCode[] = R"(
    local me = sim.getObject(':')
    function sysCall_init() print('init', sim.getRobotName()) end
    function sysCall_actuation()
      local r = sim.random()
      if r < 0.1 then
        sim.removeModel(me)
        sim.sendGlobalMessage('gone ' .. sim.getRobotName())
      elseif r > 0.9 then
        sim.copyModel(me, {sim.random() * 10, sim.random() * 10, sim.random()})
        local first = sim.getObject('/bot#0/body', {noError = true})
        if first ~= -1 then sim.sendDirectMessage(first, 'to bot#0') end
      end
    end
    function sysCall_cleanup() print('cleanup', sim.getRobotName()) end
  )";
  for (int i = 0; i < 40; ++i) w.AddRobot(kCode);
  for (int s = 0; s < 30; ++s) w.world().Step();
  EXPECT_GT(w.world().robot_count(), 40);
  *log = w.log;
  return w.world().StateHash();
}

TEST(WorldModelEditsTest, ResultsDoNotDependOnTheThreadCount) {
  std::vector<std::string> log1, log2;
  const uint64_t one = RespawnHash(1, &log1);
  const uint64_t two = RespawnHash(2, &log2);
  EXPECT_EQ(one, two);
  EXPECT_EQ(log1, log2);
}

}  // namespace
}  // namespace swarmsim
