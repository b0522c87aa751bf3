// The example worlds of issue 3: each runs, does what its README line says,
// and gives the same state hash at 1, 2 and 4 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/world_loader.h"

namespace swarmsim {
namespace {

struct WorldRun {
  uint64_t hash = 0;
  std::vector<MetricSample> metrics;
};

WorldRun RunWorld(const std::string& name, int threads, int steps,
             std::vector<std::pair<std::string, std::string>> overrides = {}) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions options;
  options.threads = threads;
  options.overrides = std::move(overrides);
  LoadedWorld loaded =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/" + name, options, registry);
  loaded.world->set_log_sink([](std::string_view) {});
  loaded.world->Start();
  WorldRun run;
  for (int i = 0; i < steps; ++i) loaded.world->Step();
  run.hash = loaded.world->StateHash();
  run.metrics = loaded.world->TakeMetrics();
  return run;
}

TEST(ExamplesTest, FirefliesSynchroniseAndAreIndependentOfThreadCount) {
  const WorldRun one = RunWorld("fireflies.yaml", 1, 400);
  ASSERT_FALSE(one.metrics.empty());
  EXPECT_EQ(one.metrics.front().name, "phase_spread");
  // Random phases at the start (spread ~0.9 for 200 robots), much closer
  // at the end, at every sample of the last 3 s.
  double last_max = 0;
  for (size_t i = one.metrics.size() - 6; i < one.metrics.size(); ++i)
    last_max = std::max(last_max, one.metrics[i].value);
  EXPECT_LT(last_max, 0.5);
  for (int threads : {2, 4}) {
    const WorldRun other = RunWorld("fireflies.yaml", threads, 400);
    EXPECT_EQ(other.hash, one.hash) << threads << " threads";
    ASSERT_EQ(other.metrics.size(), one.metrics.size());
    for (size_t i = 0; i < one.metrics.size(); ++i)
      EXPECT_EQ(other.metrics[i].value, one.metrics[i].value) << i;
  }
}

}  // namespace
}  // namespace swarmsim
