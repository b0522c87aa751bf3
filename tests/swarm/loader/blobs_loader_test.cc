// LEDs and blob cameras in world files (modules/blobs): their keys and the
// mistakes in them (file:line:col, exit code 2 from the program), scaled
// copies, a world whose scripts light their LEDs and read their cameras,
// and the docs of every key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

using BlobsLoaderTest = testing::WorldDirTest;

TEST_F(BlobsLoaderTest, BadKeysAreFileLineColumnErrors) {
  EXPECT_CONTAINS(ErrorOf("led", "  color: [1, 2, 0]\n"),
                  "thing.yaml:4:14: 'color[1]' must be at most 1 (got \"2\")");
  EXPECT_CONTAINS(ErrorOf("led", "  color: [1, 0]\n"), "thing.yaml:4:");
  EXPECT_CONTAINS(ErrorOf("led", "  color: red\n"), "thing.yaml:4:");
  EXPECT_CONTAINS(ErrorOf("led", "  radius: 0\n"), "thing.yaml:4:11:");
  EXPECT_CONTAINS(ErrorOf("led", "  on: maybe\n"), "thing.yaml:4:7:");
  EXPECT_CONTAINS(ErrorOf("led", "  colour: [1, 0, 0]\n"), "did you mean 'color'?");
  EXPECT_CONTAINS(ErrorOf("blob_camera", "  range: -1\n"), "thing.yaml:4:10:");
  EXPECT_CONTAINS(ErrorOf("blob_camera", "  range: 0\n"), "positive");
  EXPECT_CONTAINS(ErrorOf("blob_camera", "  fov_deg: 0\n"),
                  "thing.yaml:4:12: 'fov_deg' must be an angle above 0 and up to 360 degrees "
                  "(got 0)");
  EXPECT_CONTAINS(ErrorOf("blob_camera", "  fov_deg: 400\n"), "up to 360 degrees (got 400)");
  EXPECT_CONTAINS(ErrorOf("blob_camera", "  vertical_fov_deg: 181\n"),
                  "thing.yaml:4:21: 'vertical_fov_deg' must be an angle above 0 and up to 180");
  EXPECT_CONTAINS(ErrorOf("blob_camera", "  occlusion: 3\n"), "thing.yaml:4:14:");
  EXPECT_CONTAINS(ErrorOf("blob_camera", "  angle_noise_deg: -1\n"), "thing.yaml:4:20:");
  EXPECT_CONTAINS(ErrorOf("blob_camera", "  distance_noise: 2\n"), "thing.yaml:4:19:");
  EXPECT_EQ(ErrorOf("blob_camera", "  fov_deg: 360\n  vertical_fov_deg: 180\n"), "(no error)");
  EXPECT_EQ(ErrorOf("led", "  color: [0, 0, 0]\n  on: false\n"), "(no error)");
}

TEST_F(BlobsLoaderTest, TheProgramExitsWithTwoAndNamesTheKey) {
  Write("thing.yaml", "model: thing\nobjects:\n  type: blob_camera\n  range: -2\n");
  Write("world.yaml",
        "simulation: {physics: kinematic}\nmodels: [{model: thing.yaml, position: [0, 0]}]\n");
  const auto r = testing::RunProgram("run " + (dir_ / "world.yaml").string() + " --steps 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_CONTAINS(r.output, "thing.yaml:4:10:");
}

TEST_F(BlobsLoaderTest, KeysReachTheRowsAndScaledCopiesScaleRangeAndRadius) {
  Write("bot.yaml", R"(model: bot
objects:
  type: dummy
  children:
    - {name: led, type: led, color: [0, 0.5, 1], on: false, radius: 0.02}
    - {name: cam, type: blob_camera, range: 1.5, fov_deg: 90, vertical_fov_deg: 60,
       occlusion: false, enabled: false, angle_noise_deg: 2, distance_noise: 0.05}
)");
  LoadedWorld w = Load(R"(simulation: {physics: kinematic}
models:
  - {model: bot.yaml, position: [0, 0]}
  - {model: bot.yaml, position: [2, 0], scale: 2}
)");
  const LedRow& led = RowOf<LedRow>(*w.world, "/bot#0/led");
  EXPECT_EQ(led.color, (Vec3{0, 0.5, 1}));
  EXPECT_FALSE(led.on);
  EXPECT_EQ(led.radius, 0.02);
  const BlobCameraRow& cam = RowOf<BlobCameraRow>(*w.world, "/bot#0/cam");
  EXPECT_EQ(cam.range, 1.5);
  EXPECT_NEAR(cam.fov, M_PI / 2, 1e-15);
  EXPECT_NEAR(cam.vertical_fov, M_PI / 3, 1e-15);
  EXPECT_FALSE(cam.occlusion);
  EXPECT_FALSE(cam.enabled);
  EXPECT_NEAR(cam.angle_noise, 2 * M_PI / 180, 1e-15);
  EXPECT_EQ(cam.distance_noise, 0.05);
  EXPECT_EQ(RowOf<LedRow>(*w.world, "/bot#1/led").radius, 0.04);
  EXPECT_EQ(RowOf<BlobCameraRow>(*w.world, "/bot#1/cam").range, 3.0);
  EXPECT_NEAR(RowOf<BlobCameraRow>(*w.world, "/bot#1/cam").fov, M_PI / 2, 1e-15);
}

// Robots in a row 0.5 m apart; each lights its LED in a colour of its
// index and prints what its camera sees after the first step.
TEST_F(BlobsLoaderTest, ScriptsLightTheirLedsAndReadTheirCameras) {
  Write("bot.lua", R"(
    function sysCall_init()
      local i = sim.getRobotIndex()
      sim.setLedColor(sim.getObject('./led'), {i / 4, 0, 1})
      cam = sim.getObject('./cam')
    end
    function sysCall_sensing()
      if sim.getSimulationTime() == 0 then return end
      local line = ''
      for _, b in ipairs(sim.readBlobCamera(cam)) do
        line = line .. string.format(' %.2f@%.2f', b.color[1], b.bearing)
      end
      print(line)
    end
  )");
  Write("bot.yaml", R"(model: bot
objects:
  type: dummy
  script: bot.lua
  children:
    - {name: led, type: led}
    - {name: cam, type: blob_camera, range: 0.6}
)");
  LoadedWorld w = Load(R"(simulation: {physics: kinematic}
models:
  - {model: bot.yaml, position: [0, 0]}
  - {model: bot.yaml, position: [0.5, 0]}
  - {model: bot.yaml, position: [1, 0]}
)");
  std::vector<std::string> log;
  w.world->set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  w.world->Step();
  w.world->Step();
  ASSERT_EQ(log.size(), 3u);
  // bot#0 at x = 0 sees bot#1 ahead; bot#1 sees bot#0 behind and bot#2 ahead.
  EXPECT_EQ(log[0], "[bot#0]  0.25@0.00");
  EXPECT_EQ(log[1], "[bot#1]  0.50@0.00 0.00@3.14");
  EXPECT_EQ(log[2], "[bot#2]  0.25@3.14");
}

TEST_F(BlobsLoaderTest, WorldsReadmeDocumentsEveryKeyOfLedAndBlobCamera) {
  ExpectDocumented({kLedTypeName, kBlobCameraTypeName});
}

}  // namespace
}  // namespace swarmsim
