// Force sensors and paint nozzles in model files: keys, mistakes with
// file:line:col and a suggestion, and sim.readForceSensor from a script.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/force_sensor/force_sensor.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

class LoaderForcePaintTest : public testing::WorldDirTest {
 protected:
  LoadedWorld Load(const std::string& sensor_keys, const std::string& extra_world = "") {
    Write("hook.lua",
          "function sysCall_sensing()\n"
          "  local state, f, t = sim.readForceSensor(sim.getObject('./hook'))\n"
          "  sim.recordMetric('state', state)\n"
          "  sim.recordMetric('fz', f[3])\n"
          "end\n");
    Write("hanger.yaml",
          "model: hanger\n"
          "objects:\n"
          "  type: shape\n"
          "  shape: box\n"
          "  size: [0.2, 0.2, 0.05]\n"
          "  script: hook.lua\n"
          "  children:\n"
          "    - name: hook\n"
          "      type: force_sensor\n"
          "      position: [0, 0, -0.05]\n" +
              sensor_keys +
              "      children:\n"
              "        - {name: load, type: shape, shape: sphere, radius: 0.05, dynamic: true,\n"
              "           mass: 2, position: [0, 0, -0.25]}\n"
              "    - {name: pen, type: paint_nozzle, color: [1, 0, 0], radius: 0.05}\n");
    const fs::path world =
        Write("world.yaml",
              "simulation: {physics: ode, time_step: 0.01, physics_substeps: 2}\n"
              "arena: {size: 2}\n" +
                  extra_world + "models: [{model: hanger.yaml, position: [0, 0, 2]}]\n");
    return LoadWorld(world, {}, registry_);
  }
};

TEST_F(LoaderForcePaintTest, ForceSensorKeysAndScriptReading) {
  LoadedWorld w = Load("      force_threshold: 50\n      break_after: 3\n      filter_samples: 2\n",
                       "paint: {resolution: 0.02}\n");
  World& world = *w.world;
  world.set_log_sink([](std::string_view) {});
  const ObjectId hook = world.scene().FindObject("/hanger#0/hook");
  ASSERT_FALSE(hook.IsNull());
  EXPECT_EQ(force_sensor::Row(world.scene(), hook).break_after, 3);
  EXPECT_EQ(force_sensor::Row(world.scene(), hook).filter_samples, 2);
  EXPECT_EQ(force_sensor::Row(world.scene(), hook).force_threshold, 50);
  for (int i = 0; i < 30; ++i) world.Step();
  double state = -1, fz = 0;
  for (const MetricSample& m : world.TakeMetrics()) {
    if (m.name == "state") state = m.value;
    if (m.name == "fz") fz = m.value;
  }
  EXPECT_EQ(state, 1);
  EXPECT_NEAR(fz, 2 * 9.81, 0.2);
}

TEST_F(LoaderForcePaintTest, MisspelledKeyIsReportedWithSuggestion) {
  try {
    Load("      force_treshold: 50\n");
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("hanger.yaml:11:7"), std::string::npos) << what;
    EXPECT_NE(what.find("did you mean 'force_threshold'"), std::string::npos) << what;
  }
}

TEST_F(LoaderForcePaintTest, BadPaintKeyIsReported) {
  try {
    Load("", "paint: {resolutoin: 0.02}\n");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'resolution'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace swarmsim
