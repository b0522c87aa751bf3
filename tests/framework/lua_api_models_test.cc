// sim.* models (framework/lua_api_models.cc): sim.copyModel, sim.removeModel,
// sim.copyPasteObjects and sim.removeObjects refuse what is not a live
// robot's root, a bad pose, and more edits than a step may queue.
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

TEST(WorldModelEditsTest, MistakesAreClearErrors) {
  const auto error_of = [](const std::string& code) {
    ModelWorld w;
    w.AddRobot("function sysCall_actuation()\n" + code + "\nend");
    w.AddRobot(R"(
      function sysCall_actuation()
        if sim.getSimulationTime() == 0 then sim.removeModel(sim.getObject(':')) end
      end
    )");
    return ErrorOf([&] {
      for (int i = 0; i < 3; ++i) w.world().Step();
    });
  };
  // Copying a removed robot (removed at step 0).
  EXPECT_CONTAINS(error_of("if REMOVED then sim.copyModel(REMOVED) end\n"
                           "REMOVED = sim.getObject('/bot#1')"),
                  "sim.copyModel: robot handle");
  EXPECT_CONTAINS(error_of("if REMOVED then sim.copyModel(REMOVED) end\n"
                           "REMOVED = sim.getObject('/bot#1')"),
                  "is stale: the object was removed");
  // Not a robot's root.
  EXPECT_CONTAINS(error_of("sim.copyModel(sim.getObject('.'))"), "'/bot#0/body' (handle ");
  EXPECT_CONTAINS(error_of("sim.removeObjects({sim.getObject(':'), sim.getObject('.')})"),
                  "is not a robot");
  EXPECT_CONTAINS(error_of("sim.copyModel(sim.getObject(':'), {1, 'a'})"),
                  "pose {x, y, yaw} of three finite numbers expected");
  // Beyond what a world may use: refused at the call (the copy then blew up
  // "the physics", naming no line).
  EXPECT_CONTAINS(error_of("sim.copyModel(sim.getObject(':'), {2e6, 0, 0})"),
                  "sim.copyModel: the position (2e+06, 0) is beyond +-1e6 m");
  EXPECT_CONTAINS(error_of("sim.copyPasteObjects({sim.getObject(':')}, 1)"), "only 0");
  // Huge counts: a limit, not memory exhausted.
  EXPECT_CONTAINS(error_of("for i = 1, 10000 do sim.copyModel(sim.getObject(':')) end"),
                  "more than 1000 robot copies and removals queued in one step");
  EXPECT_CONTAINS(error_of("local t = {} for i = 1, 10000 do t[i] = sim.getObject(':') end\n"
                           "sim.copyPasteObjects(t)"),
                  "more than 1000 handles");
}

}  // namespace
}  // namespace swarmsim
