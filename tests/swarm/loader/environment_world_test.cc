// A world's `environment: {octomap: ...}` end to end: the example world in
// the shared real map (robots placed and kept in free space, the same hash
// at 1, 2 and 4 threads), the map seen by scripts (a proximity reading of
// sim.handle_world, range messages with line of sight). The `environment`
// key's own checks and bad map files: environment_test.cc.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/world.h"
#include "framework/world_section.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "tests/shared_maps.h"
#include "tests/swarm/run_program.h"  // FreshTempDir

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::FreshTempDir;

const std::string kCorridor = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/octomap_corridor.yaml";

const ModuleRegistry& Registry() {
  static const ModuleRegistry registry = [] {
    ModuleRegistry r;
    RegisterBuiltinModules(&r);
    return r;
  }();
  return registry;
}

LoadedWorld Load(const fs::path& file, LoadOptions options) {
  const ModuleRegistry& registry = Registry();
  LoadedWorld loaded = LoadWorld(file, options, registry);
  loaded.world->set_log_sink([](std::string_view) {});
  return loaded;
}

// Distance from (x, y) to the nearest occupied cell of `grid`.
double DistanceToCells(const EnvironmentPlaneGrid& grid, double x, double y) {
  double best = INFINITY;
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i) {
      if (!grid.at(i, j)) continue;
      const double lo_x = grid.x0 + i * grid.cell, lo_y = grid.y0 + j * grid.cell;
      const double dx = std::max({lo_x - x, 0.0, x - (lo_x + grid.cell)});
      const double dy = std::max({lo_y - y, 0.0, y - (lo_y + grid.cell)});
      best = std::min(best, std::hypot(dx, dy));
    }
  return best;
}

TEST(EnvironmentWorldTest, TheCorridorWorldPlacesAndKeepsRobotsInFreeSpace) {
  SWARMSIM_NEED_SHARED_MAP(map, "geb079.bt");
  LoadOptions options;
  options.threads = 1;
  options.overrides = {{"map", map}};
  LoadedWorld loaded = Load(kCorridor, options);
  World& world = *loaded.world;
  const Scene& scene = world.scene();
  ASSERT_NE(scene.environment(), nullptr);
  EXPECT_EQ(scene.environment()->boxes.size(), 143729u);
  ASSERT_EQ(scene.instances().size(), 50u);
  // The map's voxels at foot-bot height (0 to 0.146 m), in the plane, as
  // the octomap format's query gives them to placement.
  const EnvironmentFormatDescriptor* octomap = nullptr;
  for (const auto& format : Registry().environment_formats())
    if (format->key == "octomap") octomap = format.get();
  ASSERT_NE(octomap, nullptr);
  ASSERT_TRUE(octomap->occupied_plane);
  const EnvironmentPlaneGrid walls = octomap->occupied_plane(*scene.environment(), 1e-3, 0.145);
  // The corridor's walls are there (an empty answer would pass every check below).
  ASSERT_GT(std::count(walls.occupied.begin(), walls.occupied.end(), 1), 1000);
  auto check = [&](double keep, const char* when) {
    for (const ModelInstance& robot : scene.instances()) {
      const Vec3 p = scene.world_pose(robot.root).p;
      EXPECT_GE(DistanceToCells(walls, p.x, p.y), keep) << robot.name << " " << when;
    }
  };
  check(0.085 + 0.05, "as placed");  // radius + clearance
  world.Start();
  for (int i = 0; i < 300; ++i) world.Step();
  check(0.085 - 0.005, "after 30 s");  // in contact at most (Box2D's slop)
}

TEST(EnvironmentWorldTest, TheCorridorWorldHasOneHashAtOneTwoAndFourThreads) {
  SWARMSIM_NEED_SHARED_MAP(map, "geb079.bt");
  std::vector<uint64_t> hashes;
  for (int threads : {1, 2, 4}) {
    LoadOptions options;
    options.threads = threads;
    options.overrides = {{"map", map}};
    LoadedWorld loaded = Load(kCorridor, options);
    loaded.world->Start();
    for (int i = 0; i < 100; ++i) loaded.world->Step();
    hashes.push_back(loaded.world->StateHash());
  }
  EXPECT_EQ(hashes[1], hashes[0]);
  EXPECT_EQ(hashes[2], hashes[0]);
}

// Two robots 4 m apart across the corridor's wall (y = 3.44 m at 1 m up):
// a proximity sensor reads the wall as sim.handle_world; a range message
// with line of sight does not pass it, one without does.
TEST(EnvironmentWorldTest, ScriptsSeeTheMapInReadingsAndLineOfSight) {
  SWARMSIM_NEED_SHARED_MAP(map, "geb079.bt");
  const fs::path dir = FreshTempDir("swarmsim_env", "sight");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, octree_resolution: 0.08}\n"
                                       "environment: {octomap: \""
                                    << map
                                    << "\"}\n"
                                       "models:\n"
                                       "  - {model: probe.yaml, position: [0.001, 0.001, 1]}\n"
                                       "  - {model: probe.yaml, position: [0.001, 4.0, 1]}\n";
  std::ofstream(dir / "probe.yaml")
      << "model: probe\n"
         "objects:\n"
         "  name: body\n  type: dummy\n  script: probe.lua\n"
         "  children:\n"
         "    - {name: eye, type: proximity_sensor, range: 5, orientation_deg: [-90, 0, 0]}\n";
  std::ofstream(dir / "probe.lua") << R"(
local eye
function sysCall_init() eye = sim.getObject('./eye') end
function sysCall_actuation()
  if sim.getObjectPosition(sim.getObject('.'))[2] < 1 then
    sim.sendRangeMessage('sight', 10, true)
    sim.sendRangeMessage('any', 10, false)
    local detected, distance, point, object = sim.readProximitySensor(eye)
    sim.recordMetric('detected', detected)
    if detected == 1 then
      sim.recordMetric('distance', distance)
      sim.recordMetric('object_is_world', object == sim.handle_world and 1 or 0)
    end
  else
    while true do
      local data = sim.receiveMessage()
      if not data then break end
      sim.recordMetric(data, 1)
    end
  end
end
)";
  LoadOptions options;
  options.threads = 1;
  LoadedWorld loaded = Load(dir / "world.yaml", options);
  loaded.world->Start();
  for (int i = 0; i < 3; ++i) loaded.world->Step();
  std::map<std::string, double> last;
  std::map<std::string, int> count;
  for (const MetricSample& m : loaded.world->TakeMetrics()) {
    last[m.name] = m.value;
    ++count[m.name];
  }
  EXPECT_EQ(last["detected"], 1);
  EXPECT_NEAR(last["distance"], 3.44 - 0.001, 1e-9);
  EXPECT_EQ(last["object_is_world"], 1);
  EXPECT_GE(count["any"], 1);    // delivered without line of sight
  EXPECT_EQ(count["sight"], 0);  // hidden by the wall
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
