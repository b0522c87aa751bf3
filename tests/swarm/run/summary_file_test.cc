// summary.json's simulated time (swarm/run/summary_file.cc): the time at
// the end of the last step that finished, also when a failed step had
// moved the world's clock on; and a resumed run's own share of it.
#include "swarm/run/summary_file.h"

#include <gtest/gtest.h>

#include <memory>

#include "framework/registry.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

class StillDynamics : public DynamicsBackend {  // moves nothing
 public:
  void Build(const Scene&, const DynamicsSettings&) override {}
  void Step(Scene*, double, int) override {}
  int body_count() const override { return 0; }
};

TEST(SummaryFileTest, SimulatedTimeIsThatOfTheStepsThatFinished) {
  ModuleRegistry registry;
  registry.RegisterDynamics({"", "still", "1", "moves nothing"}, {.substeps = false},
                            [] { return std::make_unique<StillDynamics>(); });
  WorldSettings settings;
  settings.physics = "still";
  settings.time_step = 0.1;
  World world(settings, registry);
  world.Start();
  for (int k = 0; k < 5; ++k) world.Step();
  RunResult result;
  result.steps = 5;
  EXPECT_EQ(FinishedTime(world, result), world.time()) << "every step finished: the world's";
  result.steps = 4;  // the fifth failed after its physics
  EXPECT_DOUBLE_EQ(FinishedTime(world, result), 0.4);
  result.first_step = 2;  // resumed at step 2: 2 of its own finished
  result.steps = 2;
  EXPECT_DOUBLE_EQ(SimulatedThisRun(world, result), 0.2);
  result.steps = 3;
  EXPECT_DOUBLE_EQ(SimulatedThisRun(world, result), 0.3);
}

}  // namespace
}  // namespace swarmsim
