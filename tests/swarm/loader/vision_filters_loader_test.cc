// Vision sensors' filter chains as a user writes them (a `filters:` list in
// a world or model file, read through ObjectReader::Items): a rendered box
// found as a blob where it is, what scripts read, a plugin's element found
// through the world's `plugins:`, and mistakes as errors at their
// file:line:column.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/rendering/filters/filters.h"
#include "modules/rendering/objects.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

constexpr double kDeg = M_PI / 180;

// "line:column" (1-based) of the first `needle` in `text`.
std::string PositionOf(const std::string& text, const std::string& needle) {
  const size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  const size_t line_start = text.rfind('\n', at);
  const size_t line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n');
  const size_t column = at - (line_start == std::string::npos ? 0 : line_start + 1) + 1;
  return std::to_string(line) + ":" + std::to_string(column);
}

// A red box (0.5 m) 2 m ahead and `y` m to the left of a 64x48 sensor
// 0.25 m above the floor, whose filters are `filters` (YAML lines, indented
// by 8).
std::string WorldText(const std::string& filters, double y = 0, const std::string& more = "") {
  return "simulation: {physics: kinematic, time_step: 0.1}\n" + more +
         "objects:\n"
         "  - {name: box, type: shape, shape: box, size: [0.5, 0.5, 0.5], position: [2, " +
         std::to_string(y) +
         ", 0.25],\n"
         "     color: [0.9, 0.1, 0.1]}\n"
         "  - name: eye\n"
         "    type: vision_sensor\n"
         "    position: [0, 0, 0.25]\n"
         "    resolution: [64, 48]\n"
         "    filters:\n" +
         filters;
}

constexpr char kRedBlobs[] =
    "        - {type: hsv_threshold, hue: [340, 20], saturation: [0.5, 1]}\n"
    "        - {type: blobs, min_pixels: 4}\n";

class VisionFiltersLoaderTest : public testing::WorldDirTest {
 protected:
  LoadedWorld Load(const std::string& world_text, int threads = 1) {
    LoadOptions options;
    options.threads = threads;
    // The program's plugin folder is where a world finds `plugins: [example_plugin]`.
    options.plugin_directories = {std::filesystem::path(SWARMSIM_BINARY).parent_path() / "plugins"};
    LoadedWorld w = LoadWorld(Write("world.yaml", world_text), options, registry_);
    w.world->set_log_sink([](std::string_view) {});
    return w;
  }
  std::string LoadError(const std::string& world_text) {
    try {
      Load(world_text);
    } catch (const Error& e) {
      return e.what();
    }
    return "NO ERROR";
  }
  static const rendering::VisionSensorRow& Eye(World& world) {
    const ObjectId id = world.scene().FindObject("/eye");
    EXPECT_FALSE(id.IsNull());
    return *static_cast<const rendering::VisionSensorRow*>(world.scene().row_data(id));
  }
};

TEST_F(VisionFiltersLoaderTest, ARenderedBoxIsABlobWhereTheBoxIs) {
  LoadedWorld w = Load(WorldText(kRedBlobs));
  w.world->Start();
  const rendering::VisionSensorRow& eye = Eye(*w.world);
  const filters::FilterOutput& out = eye.output;
  ASSERT_EQ(out.blobs.size(), 1u);
  EXPECT_TRUE(out.triggered);
  // Straight ahead: centred horizontally; its face (0.5 m at 1.75 m) about
  // 64 (0.25 / 1.75) / tan(30 deg) pixels wide.
  const filters::Blob& blob = out.blobs[0];
  EXPECT_NEAR(blob.u, 0.5, 0.5 / 64);
  EXPECT_NEAR(blob.max_x - blob.min_x + 1, 64 * (0.25 / 1.75) / std::tan(30 * kDeg), 1.5);
  EXPECT_GT(blob.colour[0], 0.4);
  EXPECT_LT(blob.colour[1], 0.2);
  // To the left: its bearing from the centroid's ray.
  LoadedWorld left = Load(WorldText(kRedBlobs, 0.5));
  left.world->Start();
  const filters::FilterOutput& seen = Eye(*left.world).output;
  ASSERT_EQ(seen.blobs.size(), 1u);
  const Vec3 ray = filters::ImageToSensor(rendering::CameraModelOf(Eye(*left.world).lens), 64, 48,
                                          seen.blobs[0].x, seen.blobs[0].y, 1);
  EXPECT_NEAR(std::atan2(ray.y, ray.x), std::atan2(0.5, 2.0), 3 * kDeg);
}

TEST_F(VisionFiltersLoaderTest, ScriptsReadTheChainsPacketsTheSameAtAnyThreadCount) {
  Write("eye.lua", R"(
function sysCall_sensing()
  local result, packet1, blobs = sim.readVisionSensor(sim.getObject('/eye'))
  assert(result == 1 and #packet1 == 15 and blobs[1] == 1 and blobs[2] == 10)
end
)");
  std::vector<std::vector<double>> packets[2];
  for (int threads : {1, 2}) {
    LoadedWorld w = Load(WorldText(kRedBlobs, 0.3) + "    script: eye.lua\n", threads);
    w.world->Start();
    for (int i = 0; i < 3; ++i) w.world->Step();
    packets[threads - 1] = Eye(*w.world).output.packets;
  }
  ASSERT_EQ(packets[0].size(), 2u);
  EXPECT_EQ(packets[0], packets[1]);
}

TEST_F(VisionFiltersLoaderTest, APluginsElementIsFoundThroughTheWorldsPlugins) {
  LoadedWorld w = Load(WorldText("        - {type: invert}\n", 0, "plugins: [example_plugin]\n"));
  w.world->Start();
  const rendering::VisionSensorRow& eye = Eye(*w.world);
  ASSERT_EQ(eye.output.image.rgb.size(), eye.image.rgb.size());
  for (size_t i = 0; i < eye.image.rgb.size(); ++i)
    ASSERT_EQ(eye.output.image.rgb[i], 255 - eye.image.rgb[i]) << i;
  // Without the plugin: unknown.
  EXPECT_CONTAINS(LoadError(WorldText("        - {type: invert}\n")), "'type' must be one of");
}

TEST_F(VisionFiltersLoaderTest, MistakesAreErrorsAtTheirFileLineAndColumn) {
  // An unknown element, with a suggestion.
  std::string world = WorldText("        - {type: blob}\n");
  EXPECT_CONTAINS(LoadError(world), "world.yaml:" + PositionOf(world, "blob}") +
                                        ": 'type' must be one of grayscale, resize");
  EXPECT_CONTAINS(LoadError(world), R"((got "blob"); did you mean 'blobs'?)");
  // Kinds that do not fit, at the element that needs another.
  world = WorldText(
      "        - {type: grayscale}\n"
      "        - {type: blobs, min_pixels: 4}\n");
  EXPECT_CONTAINS(LoadError(world), "world.yaml:" + PositionOf(world, "blobs,") +
                                        ": 'blobs' needs a mask; 'grayscale' gives a grey image: "
                                        "put a threshold before it");
  // Bad values.
  world = WorldText("        - {type: color_threshold, color: [1, 0, 2]}\n");
  EXPECT_CONTAINS(LoadError(world), "world.yaml:" + PositionOf(world, "2]}"));
  world = WorldText("        - {type: resize, width: 0, height: 4}\n");
  EXPECT_CONTAINS(LoadError(world), "world.yaml:" + PositionOf(world, "0, h"));
  // A key the element does not take, with a suggestion and the item named.
  world = WorldText(
      "        - {type: color_threshold, color: [1, 0, 0]}\n"
      "        - {type: blobs, min_pixel: 4}\n");
  EXPECT_CONTAINS(LoadError(world), "world.yaml:" + PositionOf(world, "min_pixel") +
                                        ": unknown key 'min_pixel' in filters[1] of object 'eye'; "
                                        "did you mean 'min_pixels'?");
  // A misspelt 'type'.
  world = WorldText("        - {tpye: blobs}\n");
  EXPECT_CONTAINS(LoadError(world), "world.yaml:" + PositionOf(world, "tpye") +
                                        ": unknown key 'tpye' in filters[0] of object 'eye'; did "
                                        "you mean 'type'?");
  // An item that is not a map; a list that is not a list.
  world = WorldText("        - blobs\n");
  EXPECT_CONTAINS(LoadError(world), "world.yaml:" + PositionOf(world, "blobs") +
                                        ": filters[0] of object 'eye' must be a mapping");
  EXPECT_CONTAINS(LoadError(WorldText("          blobs\n")), "'filters' must be a list of maps");
}

}  // namespace
}  // namespace swarmsim
