// Plugin phase callbacks (framework/plugin_api.h, SwarmsimPhaseCallback):
// run at fixed points of each step, with the world interface plugins see.
// Apart from world.cc, like world_plugin_sensors.cc, so that the World does
// not include that interface (plugin_world_api.cc includes world.h).
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/plugin_world_api.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/world.h"

namespace swarmsim {
namespace {}  // namespace

void World::CallPhaseCallbacks(const std::vector<const PhaseCallback*>& callbacks) {
  // Whole-world callbacks on this thread, per-robot ones fanned out over the
  // robots; the lowest robot's error wins, whatever the thread count.
  auto call = [&](const PhaseCallback& callback, int robot, std::string* error) {
    const SwarmsimCallContext context{robot, 0, this, PluginWorldApi()};
    char message[512] = {0};
    if (callback.function(&context, message, sizeof message, callback.user_data) != 0)
      *error = callback.name + (robot >= 0 ? " (robot " + scene_.instance(robot).name + ")" : "") +
               ": " + (message[0] ? message : "the plugin callback failed");
  };
  for (const PhaseCallback* callback : callbacks) {
    std::string error;
    if (!callback->per_robot) {
      call(*callback, -1, &error);
    } else {
      const auto& instances = scene_.instances();
      std::vector<std::string> errors(instances.size());
      scheduler_->ParallelFor(0, static_cast<int64_t>(instances.size()), kRobotGrain,
                              [&](int64_t begin, int64_t end) {
                                for (int64_t r = begin; r < end; ++r)
                                  if (instances[r].alive)
                                    call(*callback, static_cast<int>(r), &errors[r]);
                              });
      for (std::string& e : errors)
        if (!e.empty() && error.empty()) error = std::move(e);
    }
    if (!error.empty()) throw Error(error);
  }
}

bool World::IsListedSwarmMetric(std::string_view name) const {
  if (find_module(name) == nullptr) return false;
  const ModuleDescriptor* d = registry().FindModule(name);
  return d != nullptr && d->info.kind == "metric";
}

bool World::RecordPluginMetric(int robot, std::string_view name, double value) {
  if (!recording_ || name.empty() || robot < -1 || robot >= robot_count()) return false;
  // Under a swarm metric's name the rows of both would be one metric (as
  // sim.recordMetric refuses).
  if (IsListedSwarmMetric(name)) return false;
  const std::lock_guard lock(plugin_metrics_mutex_);
  plugin_metrics_.push_back({step_count_, time_, robot, std::string(name), value});
  return true;
}

}  // namespace swarmsim
