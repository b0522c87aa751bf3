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
    Make(threads, std::move(settings));
  }
  // The same with the world's seed.
  ScriptWorld(int threads, uint64_t seed, WorldSettings settings = {})
      : registry_(testing::NullRegistry()) {
    settings.seed = seed;
    Make(threads, std::move(settings));
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
  // A wheeled robot, 1 m along x from the last one: a root dummy named like
  // the instance carrying a `body` shape with joints `leftMotor` and
  // `rightMotor`; `code` (from `path`) attached to the body unless empty.
  // Returns the body.
  ObjectId AddWheeledRobot(const std::string& name, const std::string& code,
                           const std::string& path = "scripts/robot.lua") {
    const ObjectId root = scene().AddDummy(name, {}, {{next_x_, 0, 0}, {}});
    next_x_ += 1;
    const ObjectId body = scene().AddShape("body", root, {}, {});
    scene().AddJoint("leftMotor", body, {{0, 0.05, 0}, {}}, {});
    scene().AddJoint("rightMotor", body, {{0, -0.05, 0}, {}}, {});
    scene().MakeModelInstance(root, "bot", name);
    if (!code.empty()) scene().AttachScript(body, Source(path, code));
    return body;
  }
  ObjectId Joint(const std::string& path) { return scene().FindObject(path); }
  void Steps(int n) {
    for (int i = 0; i < n; ++i) world_->Step();
  }
  std::vector<std::string> log;

 private:
  void Make(int threads, WorldSettings settings) {
    settings.physics = "null";
    settings.time_step = 0.1;
    settings.threads = threads;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
  }

  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
  double next_x_ = 0;
};

}  // namespace swarmsim::script_test
