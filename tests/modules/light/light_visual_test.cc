// A light source as the recording, snapshots and the viewer show it: listed
// in the recording's scene as a `light` visual of its radius and colour,
// its switch recorded step by step as a script turns it off and on, and
// drawn glowing in a snapshot while it is on (dark while it is off).
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/light/light.h"
#include "modules/paint/png_io.h"
#include "modules/rendering/video/recorder.h"
#include "swarm/record/reader.h"
#include "swarm/record/writer.h"
#include "tests/modules/module_world.h"

namespace swarmsim {
namespace {

using testing::TempDir;

// A magenta lamp (radius 0.1 m, 0.3 m up) over the middle of a 2 m floor
// framed by two walls, switched by its script: off in its 2nd step, on again
// in its 3rd (when `script`).
struct LampWorld {
  explicit LampWorld(bool on, bool script) {
    RegisterBuiltinModules(&registry);
    WorldSettings settings;
    settings.physics = "kinematic";
    world = std::make_unique<World>(settings, registry);
    world->set_log_sink([](std::string_view) {});
    Scene& scene = world->scene();
    ObjectType type;
    EXPECT_TRUE(scene.FindType(light::kLightSourceTypeName, &type));
    light::LightSourceRow row;
    row.on = on;
    row.settings.Edit().color = {1, 0, 1};
    row.settings.Edit().radius = 0.1;
    lamp = scene.AddObject(type, "lamp", {}, {{0, 0, 0.3}, {}}, &row);
    if (script)
      scene.AttachScript(lamp, std::make_shared<const ScriptSource>(ScriptSource{
                                   "lamp.lua",
                                   "local n = 0\n"
                                   "function sysCall_actuation()\n"
                                   "  n = n + 1\n"
                                   "  sim.setLightSourceOn(sim.getObject('.'), n ~= 2)\n"
                                   "end\n"}));
    ShapeData wall;
    wall.kind = ShapeKind::kBox;
    wall.size = {2, 0.05, 0.1};
    wall.color = {0.5, 0.5, 0.5};
    scene.AddShape("wall_s", {}, {{0, -1, 0.05}, {}}, wall);
    scene.AddShape("wall_n", {}, {{0, 1, 0.05}, {}}, wall);
  }
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  ObjectId lamp;
};

TEST(LightVisualTest, IsRecordedAsALightWithItsSwitchStepByStep) {
  TempDir dir;
  LampWorld w(/*on=*/true, /*script=*/true);
  record::RecordSettings settings;
  settings.out_dir = dir.path();
  record::RunRecorder* recorder = record::AddRecorder(w.world.get(), settings);
  w.world->Start();
  for (int i = 0; i < 3; ++i) w.world->Step();
  recorder->Finish(3, "ok", "");

  record::RecordingPlayer player(dir.path());
  ASSERT_TRUE(player.Next());  // step 0
  const nlohmann::json scene = nlohmann::json::parse(player.scene_json());
  const nlohmann::json& objects = scene["objects"];
  ASSERT_EQ(objects.size(), 3u);
  EXPECT_EQ(objects[0]["name"], "lamp");
  EXPECT_EQ(objects[0]["type"], "light_source");
  EXPECT_EQ(objects[0]["visual"], "light");
  EXPECT_EQ(objects[0]["radius"], 0.1);
  EXPECT_EQ(objects[0]["color"], nlohmann::json::parse("[1.0, 0.0, 1.0]"));
  // Its colour word, r | g << 8 | b << 16 | on << 24: on, off after the
  // script's 2nd step, on again after its 3rd.
  std::vector<uint32_t> words{player.color_rgba(0)};
  while (player.Next()) words.push_back(player.color_rgba(0));
  EXPECT_EQ(words, (std::vector<uint32_t>{0x01ff00ff, 0x01ff00ff, 0x00ff00ff, 0x01ff00ff}));
}

// The magenta pixels of a snapshot after one step.
int MagentaPixels(bool on, const std::filesystem::path& dir) {
  LampWorld w(on, /*script=*/false);
  video::RecorderSettings settings;
  settings.out_dir = dir;
  settings.snapshot_every = 1;
  settings.width = 160;
  settings.height = 120;
  w.world->AddModule("recorder", &settings);
  w.world->Start();
  w.world->Step();
  w.world->WriteOutputs(dir);
  const paint::RgbImage image = paint::ReadPng(dir / "snapshots" / "step_000001.png");
  int magenta = 0;
  for (size_t i = 0; i + 2 < image.rgb.size(); i += 3)
    magenta += image.rgb[i] > 180 && image.rgb[i + 1] < 100 && image.rgb[i + 2] > 180;
  return magenta;
}

TEST(LightVisualTest, GlowsInASnapshotWhileOn) {
  TempDir lit, dark;
  EXPECT_GT(MagentaPixels(true, lit.path()), 20);
  EXPECT_EQ(MagentaPixels(false, dark.path()), 0);
}

}  // namespace
}  // namespace swarmsim
