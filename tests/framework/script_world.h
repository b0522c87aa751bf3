// What the script host's tests build on: a World with null modules (fakes.h)
// whose robots are dummies carrying a script, and whose prints land in `log`.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "tests/framework/fakes.h"

namespace swarmsim::script_test {

inline std::shared_ptr<const ScriptSource> Source(std::string path, std::string code) {
  return std::make_shared<const ScriptSource>(ScriptSource{std::move(path), std::move(code)});
}

// A world with null modules whose script output lands in `log`.
class ScriptWorld {
 public:
  explicit ScriptWorld(int threads = 1, WorldSettings settings = {},
                       ModuleRegistry registry = testing::NullRegistry())
      : registry_(std::move(registry)) {
    settings.physics = "null";
    settings.time_step = 0.1;
    settings.threads = threads;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
  }
  World& world() { return *world_; }
  Scene& scene() { return world_->scene(); }

  // A robot: root dummy at (x, y) with heading `yaw` carrying a `body`
  // dummy with `code` attached (unless empty). Returns the body.
  ObjectId AddRobot(const std::string& name, const std::string& code, double x = 0, double y = 0,
                    double yaw = 0) {
    const ObjectId root =
        scene().AddDummy(name, {}, {{x, y, 0}, Quat::FromAxisAngle({0, 0, 1}, yaw)});
    const ObjectId body = scene().AddDummy("body", root, {});
    scene().MakeModelInstance(root, "bot", name);
    if (!code.empty()) scene().AttachScript(body, Source("scripts/robot.lua", code));
    return body;
  }
  void Steps(int n) {
    for (int i = 0; i < n; ++i) world_->Step();
  }
  std::vector<std::string> log;

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
};

}  // namespace swarmsim::script_test
