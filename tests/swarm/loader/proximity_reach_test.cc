// Walls kilometres from the origin, inside the documented coordinate limit
// (1e6 m), are seen by proximity sensors (issue 26): the run used to stop
// with "static shape '/wall_b' lies outside the octree's reach".
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

TEST(ProximityReachTest, WallsKilometresApartAreBothSeen) {
  const fs::path dir = testing::FreshTempDir("swarmsim_reach", "walls");
  fs::create_directories(dir);
  // wall_a 2 km west, wall_b 2 km east: 80,000 voxels apart at 0.05 m,
  // more than the octree's 65,536; each has a probe 1 m in front of it.
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: kinematic, time_step: 0.1}\n"
         "obstacles:\n"
         "  - {name: wall_a, shape: box, size: [0.2, 4, 2], position: [-2000, 0, 1]}\n"
         "  - {name: wall_b, shape: box, size: [0.2, 4, 2], position: [2000, 0, 1]}\n"
         "models:\n"
         "  - {model: probe.yaml, position: [-1998.9, 0, 1], heading_deg: 180}\n"
         "  - {model: probe.yaml, position: [1998.9, 0, 1]}\n";
  std::ofstream(dir / "probe.yaml")
      << "model: probe\n"
         "objects:\n"
         "  name: body\n  type: dummy\n  script: probe.lua\n"
         "  children:\n"
         "    - {name: eye, type: proximity_sensor, range: 5, orientation_deg: [0, 90, 0]}\n";
  std::ofstream(dir / "probe.lua") << R"(
local eye
function sysCall_init() eye = sim.getObject('./eye') end
function sysCall_sensing()
  local detected, distance = sim.readProximitySensor(eye)
  sim.recordMetric('detected', detected)
  if detected == 1 then sim.recordMetric('distance', distance) end
end
)";
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions options;
  options.threads = 1;
  LoadedWorld loaded = LoadWorld(dir / "world.yaml", options, registry);
  ASSERT_NO_THROW(loaded.world->Start());
  loaded.world->Step();
  int detected = 0, readings = 0;
  for (const MetricSample& m : loaded.world->TakeMetrics()) {
    if (m.name == "detected") ++readings, detected += m.value == 1;
    if (m.name == "distance") {
      EXPECT_NEAR(m.value, 1.0, 1e-6);
    }
  }
  EXPECT_EQ(readings, 2);
  EXPECT_EQ(detected, 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
