#include "framework/plugin_controllers.h"

#include <cstdio>
#include <cstring>
#include <exception>

#include "framework/error.h"
#include "framework/messaging.h"
#include "framework/plugin_world_api.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/world.h"

namespace swarmsim {

namespace {
constexpr size_t kErrorSize = 1024;
}  // namespace

void ModuleRegistry::RegisterController(ModuleInfo info, PluginControllerType type) {
  if (FindController(type.name) != nullptr)
    throw Error("native controller '" + type.name + "' is registered twice");
  info.kind = "controller";
  modules_.push_back(std::move(info));
  controllers_.push_back(std::make_shared<const PluginControllerType>(std::move(type)));
}

const PluginControllerType* ModuleRegistry::FindController(std::string_view name) const {
  for (const auto& c : controllers_)
    if (c->name == name) return c.get();
  return nullptr;
}

std::vector<std::string> ModuleRegistry::ControllerNames() const {
  std::vector<std::string> names;
  for (const auto& c : controllers_) names.push_back(c->name);
  return names;
}

void PluginControllers::Assign(int robot, const PluginControllerType* type,
                               bool in_place_of_scripts) {
  if (robot >= static_cast<int>(robots_.size())) robots_.resize(static_cast<size_t>(robot) + 1);
  robots_[robot] = Robot{};
  robots_[robot].type = type;
  robots_[robot].in_place_of_scripts = in_place_of_scripts;
}

SwarmsimCallContext PluginControllers::Context(int robot) const {
  const Scene& scene = world_->scene();
  return {robot, scene.instance(robot).root.ToInteger(), world_, PluginWorldApi()};
}

void PluginControllers::Init(int first) {
  const int count = static_cast<int>(robots_.size());
  if (first >= count) return;
  const auto& instances = world_->scene().instances();
  world_->scheduler().ParallelFor(first, count, kRobotGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      Robot& robot = robots_[r];
      if (robot.type == nullptr || robot.running || !instances[r].alive) continue;
      robot.running = true;
      if (robot.in_place_of_scripts) {
        Rng& rng = world_->runtime(static_cast<int>(r)).rng;
        rng.NextU64(), rng.NextU64();
      }
      if (robot.type->init == nullptr) continue;
      const SwarmsimCallContext context = Context(static_cast<int>(r));
      char error[kErrorSize] = "";
      int status;
      try {  // a plugin breaking the rule (no exception leaves it) still gets a message
        status =
            robot.type->init(&context, &robot.state, error, sizeof error, robot.type->user_data);
      } catch (const std::exception& e) {
        std::snprintf(error, sizeof error, "a C++ exception left the plugin: %s", e.what());
        status = -1;
      }
      if (status != 0) Fail(static_cast<int>(r), "init", error);
    }
  });
}

void PluginControllers::CallStep(int r) {
  Robot& robot = robots_[r];
  const SwarmsimCallContext context = Context(r);
  char error[kErrorSize];
  error[0] = 0;
  int status;
  try {
    status = robot.type->step(&context, robot.state, error, sizeof error, robot.type->user_data);
  } catch (const std::exception& e) {
    std::snprintf(error, sizeof error, "a C++ exception left the plugin: %s", e.what());
    status = -1;
  }
  if (status != 0) Fail(r, "step", error);
}

void PluginControllers::Fail(int r, const char* what, const char* message) {
  Robot& robot = robots_[r];
  RobotRuntime& rt = world_->runtime(r);
  const std::string text = world_->scene().instance(r).name + ": native controller '" +
                           robot.type->name + "' (" + robot.type->plugin + "), in " + what + ": " +
                           (message[0] != 0 ? std::string(message, strnlen(message, kErrorSize - 1))
                                            : std::string("failed without a message"));
  if (world_->settings().on_script_error == ScriptErrorPolicy::kDisableScript) {
    // Its cleanup still runs (the state init made is the plugin's to free).
    rt.log.Add("error, native controller disabled: " + text);
    rt.disabled.push_back(text);
    if (robot.type->cleanup != nullptr) {
      const SwarmsimCallContext context = Context(r);
      robot.type->cleanup(&context, robot.state, robot.type->user_data);
    }
    robot.running = false;
    robot.state = nullptr;
    return;
  }
  rt.error = text;
}

void PluginControllers::Cleanup(int r) {
  if (r >= static_cast<int>(robots_.size())) return;
  Robot& robot = robots_[r];
  if (!robot.running) return;
  robot.running = false;
  if (robot.type->cleanup != nullptr) {
    const SwarmsimCallContext context = Context(r);
    robot.type->cleanup(&context, robot.state, robot.type->user_data);
  }
  robot.state = nullptr;
}

void PluginControllers::CleanupAll() {
  for (int r = 0; r < static_cast<int>(robots_.size()); ++r) Cleanup(r);
}

int PluginControllers::Receive(int r, SwarmsimMessage* out) {
  if (r < 0 || r >= static_cast<int>(robots_.size()) || out == nullptr) return 0;
  Robot& robot = robots_[r];
  const Messaging& messaging = world_->messaging();
  if (robot.round != messaging.round()) robot.round = messaging.round(), robot.next = 0;
  const ObjectId self = world_->scene().instance(r).root;
  const std::vector<ReceivedMessage>& inbox = world_->messaging().robot_mail(r).inbox;
  const std::vector<Message>& messages = messaging.messages();
  while (robot.next < inbox.size()) {
    const ReceivedMessage& received = inbox[robot.next++];
    const Message& m = messages[received.message];
    if (m.scope == MessageScope::kDirect ? m.target != self : m.sender == self) continue;
    out->data = m.data.data();
    out->size = m.data.size();
    out->sender = m.sender.IsNull() ? -1 : m.sender.ToInteger();  // -1: the main script
    out->has_geometry = received.has_geometry ? 1 : 0;
    out->distance = received.has_geometry ? received.distance : 0;
    out->bearing = received.has_geometry ? received.bearing : 0;
    return 1;
  }
  return 0;
}

}  // namespace swarmsim
