// framework/README.md's worked example, "Adding a sensor: one folder, one
// line": the ground sensor (modules/ground_sensor), registered with its one
// line in modules/builtin.cc and nothing else changed, is sensed, read by
// scripts, recorded with its colour changing step by step, and drawn in a
// snapshot; an object of a type that declares no visual is recorded as a
// plain frame.
#include "modules/ground_sensor/ground_sensor.h"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "framework/floor_layer.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/paint/png_io.h"
#include "modules/rendering/video/recorder.h"
#include "swarm/record/reader.h"
#include "swarm/record/writer.h"
#include "tests/modules/module_world.h"

namespace swarmsim::ground_sensor {
namespace {

using testing::TempDir;

// A type that declares no visual (no rows either): a robot's root of it is
// a plain frame in a recording.
constinit const ObjectTypeDescriptor kPlainType{.name = "plain", .description = "no visual"};

// A floor layer of 2 x 2 m: red where x < 0, green where x >= 0.
class HalfAndHalfFloor final : public FloorLayer {
 public:
  HalfAndHalfFloor() : rgb_(3 * kSide * kSide) {
    for (int r = 0; r < kSide; ++r)
      for (int c = 0; c < kSide; ++c) rgb_[3 * (r * kSide + c) + (c < kSide / 2 ? 0 : 1)] = 255;
  }
  FloorArea floor_area() const override { return {-1, -1, 1, 1, 0.1, kSide, kSide, {1, 1, 1}}; }
  std::span<const uint8_t> floor_rgb() const override { return rgb_; }
  bool floor_marked(int, int) const override { return true; }

 private:
  static constexpr int kSide = 20;
  std::vector<uint8_t> rgb_;
};

// A world of the built-in modules (ground_sensor::Register is one line of them).
struct SensorWorld {
  explicit SensorWorld(bool with_sensor = true) {
    RegisterBuiltinModules(&registry);
    registry.RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
        std::shared_ptr<const ObjectTypeDescriptor>(), &kPlainType));
    WorldSettings settings;
    settings.physics = "kinematic";
    world = std::make_unique<World>(settings, registry);
    world->set_log_sink([](std::string_view) {});
    Scene& scene = world->scene();
    ObjectType plain, sensor;
    EXPECT_TRUE(scene.FindType("plain", &plain));
    EXPECT_TRUE(scene.FindType(kTypeName, &sensor));
    robot = scene.AddObject(plain, "bot", {}, {{-0.5, 0, 0}, {}}, nullptr);
    scene.MakeModelInstance(robot, "bot", "bot#0");
    ShapeData body;
    body.kind = ShapeKind::kBox;
    body.size = {0.1, 0.1, 0.05};
    scene.AddShape("body", robot, {{0.3, 0, 0.025}, {}}, body);
    if (with_sensor) {
      GroundSensorRow row;
      row.settings.Edit().radius = 0.1;
      row.settings.Edit().mode = Mode::kColor;
      eye = scene.AddObject(sensor, "eye", robot, {{0, 0, 0.06}, {}}, &row);
    }
    // Something outside the robot to frame the arena by.
    ShapeData wall;
    wall.kind = ShapeKind::kBox;
    wall.size = {2, 0.05, 0.1};
    scene.AddShape("wall", {}, {{0, -1, 0.05}, {}}, wall);
  }
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  ObjectId robot, eye;
};

TEST(GroundSensorTest, ScriptsReadTheFloorUnderIt) {
  SensorWorld w;
  HalfAndHalfFloor floor;
  w.world->set_floor_layer(&floor);
  std::vector<std::string> log;
  w.world->set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  w.world->scene().AttachScript(
      w.robot,
      std::make_shared<const ScriptSource>(ScriptSource{
          "bot.lua",
          "function sysCall_sensing()\n"
          "  print(string.format('%g %g %g %g', sim.readGroundSensor(sim.getObject('./eye'))))\n"
          "end\n"}));
  w.world->Start();
  w.world->Step();  // x = -0.5: red
  w.world->scene().SetLocalPose(w.robot, {{0.5, 0, 0}, {}});
  w.world->Step();  // x = 0.5: green
  ASSERT_EQ(log.size(), 2u);
  // value (the colour's grey level 0.299 r + 0.587 g + 0.114 b), r, g, b.
  EXPECT_NE(log[0].find("0.299 1 0 0"), std::string::npos) << log[0];
  EXPECT_NE(log[1].find("0.587 0 1 0"), std::string::npos) << log[1];
}

TEST(GroundSensorTest, IsRecordedWithItsColourStepByStep) {
  TempDir dir;
  SensorWorld w;
  HalfAndHalfFloor floor;
  w.world->set_floor_layer(&floor);
  record::RecordSettings settings;
  settings.out_dir = dir.path();
  record::RunRecorder* recorder = record::AddRecorder(w.world.get(), settings);
  w.world->Start();  // step 0: not sensed yet (black)
  w.world->Step();   // step 1: over red
  w.world->scene().SetLocalPose(w.robot, {{0.5, 0, 0}, {}});
  w.world->Step();  // step 2: over green
  recorder->Finish(2, "ok", "");

  record::RecordingPlayer player(dir.path());
  ASSERT_TRUE(player.Next());  // step 0, with the scene in force
  // The robot's root (a type with no visual) is a frame; the body and the
  // sensor are listed as their types declare them.
  const nlohmann::json scene = nlohmann::json::parse(player.scene_json());
  const nlohmann::json& objects = scene["templates"][0]["objects"];
  ASSERT_EQ(objects.size(), 3u);
  EXPECT_EQ(objects[0]["type"], "frame");
  EXPECT_FALSE(objects[0].contains("visual"));
  EXPECT_EQ(objects[1]["type"], "shape");
  EXPECT_EQ(objects[1]["visual"], "box");
  EXPECT_EQ(objects[2]["type"], "ground_sensor");
  EXPECT_EQ(objects[2]["name"], "eye");
  EXPECT_EQ(objects[2]["visual"], "cylinder");
  EXPECT_EQ(objects[2]["size"], nlohmann::json::parse("[0.1, 0, 0.002]"));
  // Its colour, r | g << 8 | b << 16 | on << 24, at each step.
  std::vector<uint32_t> colours{player.color_rgba(2)};
  while (player.Next()) colours.push_back(player.color_rgba(2));
  EXPECT_EQ(colours, (std::vector<uint32_t>{0x01000000, 0x010000ff, 0x0100ff00}));
  // An object of a type without a visual outside any robot is not recorded:
  // the wall (a shape) is the only scene object.
  ASSERT_EQ(scene["objects"].size(), 1u);
  EXPECT_EQ(scene["objects"][0]["name"], "wall");
}

// The dark pixels of the arena's snapshot at step 1 (the sensor reads black
// without a floor layer; nothing else is dark).
int DarkPixels(bool with_sensor, const std::filesystem::path& dir) {
  SensorWorld w(with_sensor);
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
  int dark = 0;
  for (size_t i = 0; i + 2 < image.rgb.size(); i += 3)
    dark += image.rgb[i] < 40 && image.rgb[i + 1] < 40 && image.rgb[i + 2] < 40;
  return dark;
}

TEST(GroundSensorTest, IsDrawnInASnapshot) {
  TempDir with, without;
  EXPECT_GT(DarkPixels(true, with.path()), 20);
  EXPECT_EQ(DarkPixels(false, without.path()), 0);
}

}  // namespace
}  // namespace swarmsim::ground_sensor
