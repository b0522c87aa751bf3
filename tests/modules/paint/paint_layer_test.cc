// The floor paint layer: a nozzle moved along a known path paints exactly
// the pixels within its radius of the path's points; the PNG decodes with
// the layer's size and pixels; the image is the same at 1 and 2 threads;
// others see it as the world's floor layer.
#include "modules/paint/paint_layer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/floor_layer.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/paint/paint_nozzle.h"
#include "modules/paint/png_io.h"

namespace swarmsim::paint {
namespace {

struct Fixture {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  PaintLayer* layer = nullptr;
  explicit Fixture(int threads, const PaintSettings& settings) {
    RegisterBuiltinModules(&registry);
    WorldSettings s;
    s.physics = "kinematic";
    s.time_step = 0.1;
    s.threads = threads;
    world = std::make_unique<World>(s, registry);
    world->set_log_sink([](std::string_view) {});
    auto owned = std::make_unique<PaintLayer>(world.get(), settings);
    layer = owned.get();
    world->AddObserver(std::move(owned));
  }
  Scene& scene() { return world->scene(); }
  // A robot: a dummy root with a nozzle 0.05 m above the floor.
  ObjectId AddRobot(int index, const PaintNozzleData& nozzle) {
    const ObjectId root = scene().AddDummy("bot", {}, {{0, 0, 0.1}, {}});
    ObjectType nozzle_type;
    EXPECT_TRUE(scene().FindType(kPaintNozzleTypeName, &nozzle_type));
    scene().AddObject(nozzle_type, "nozzle", root, {{0, 0, -0.05}, {}}, &nozzle);
    scene().MakeModelInstance(root, "bot", "bot#" + std::to_string(index));
    return root;
  }
};

PaintSettings Area() {
  PaintSettings s;
  s.resolution = 0.01;
  s.min_x = -0.5;
  s.min_y = -0.25;
  s.max_x = 0.5;
  s.max_y = 0.25;
  return s;
}

TEST(PaintLayerTest, KnownPathPaintsExactlyThosePixels) {
  Fixture f(1, Area());
  ASSERT_EQ(f.layer->width(), 100);
  ASSERT_EQ(f.layer->height(), 50);
  PaintNozzleData nozzle;
  nozzle.radius = 0.03;
  nozzle.color = {1, 0, 0};
  const ObjectId bot = f.AddRobot(0, nozzle);
  // Drive along y = 0.1 - 0.02 x from x = -0.3 to 0.3 in 0.013 m steps.
  std::vector<Vec3> path;
  for (int i = 0; i <= 46; ++i) {
    const double x = -0.3 + 0.013 * i;
    path.push_back({x, 0.1 - 0.02 * x, 0.1});
  }
  f.world->Start();
  for (const Vec3& p : path) {
    f.scene().SetWorldPose(bot, {p, {}});
    f.world->Step();
  }
  int64_t expected = 0;
  for (int row = 0; row < f.layer->height(); ++row)
    for (int col = 0; col < f.layer->width(); ++col) {
      const Vec3 c = f.layer->PixelCentre(col, row);
      bool hit = false;
      for (const Vec3& p : path) hit |= std::hypot(c.x - p.x, c.y - p.y) <= 0.03;
      expected += hit;
      ASSERT_EQ(f.layer->painted(col, row), hit) << "pixel " << col << ", " << row;
      if (hit) {
        const uint8_t* px = &f.layer->rgb()[3 * (row * f.layer->width() + col)];
        EXPECT_EQ(px[0], 255);
        EXPECT_EQ(px[1], 0);
      }
    }
  EXPECT_EQ(f.layer->painted_count(), expected);
  EXPECT_GT(expected, 60 * 6);  // a 0.6 m stroke about 0.06 m wide
}

TEST(PaintLayerTest, DisabledNozzleAndNozzleBelowFloorPaintNothing) {
  Fixture f(1, Area());
  PaintNozzleData off;
  off.enabled = false;
  f.AddRobot(0, off);
  const ObjectId low = f.AddRobot(1, {});
  f.world->Start();
  f.scene().SetWorldPose(low, {{0, 0, 0.01}, {}});  // nozzle at z = -0.04
  f.world->Step();
  EXPECT_EQ(f.layer->painted_count(), 0);
}

TEST(PaintLayerTest, PngDecodesWithTheLayersSizeAndPixels) {
  Fixture f(1, Area());
  PaintNozzleData nozzle;
  nozzle.color = {0, 0.5, 1};
  f.AddRobot(0, nozzle);
  f.world->Start();
  f.world->Step();
  const auto dir = std::filesystem::temp_directory_path() / "swarmsim_paint_test";
  std::filesystem::create_directories(dir);
  f.world->WriteOutputs(dir);
  const RgbImage image = ReadPng(dir / "paint.png");
  EXPECT_EQ(image.width, 100);
  EXPECT_EQ(image.height, 50);
  EXPECT_EQ(image.rgb, f.layer->rgb());
  const uint8_t* centre = &image.rgb[3 * (25 * 100 + 50)];
  EXPECT_EQ(centre[0], 0);
  EXPECT_EQ(centre[1], 128);
  EXPECT_EQ(centre[2], 255);
  std::filesystem::remove_all(dir);
}

// 64 robots on overlapping circles, each its own colour: overlaps are
// resolved in robot order, so the image does not depend on the thread count.
std::vector<uint8_t> PaintCircles(int threads) {
  Fixture f(threads, Area());
  std::vector<ObjectId> bots;
  for (int i = 0; i < 64; ++i) {
    PaintNozzleData nozzle;
    nozzle.radius = 0.02;
    nozzle.color = {i / 63.0, 1 - i / 63.0, 0.5};
    bots.push_back(f.AddRobot(i, nozzle));
  }
  f.world->Start();
  for (int step = 0; step < 40; ++step) {
    for (int i = 0; i < 64; ++i) {
      const double a = 0.1 * step + i;
      f.scene().SetWorldPose(bots[i],
                             {{0.2 * std::cos(a) + 0.003 * i, 0.15 * std::sin(a), 0.1}, {}});
    }
    f.world->Step();
  }
  return f.layer->rgb();
}

TEST(PaintLayerTest, SameImageAtOneAndTwoThreads) { EXPECT_EQ(PaintCircles(1), PaintCircles(2)); }

}  // namespace
}  // namespace swarmsim::paint

namespace swarmsim::paint {
namespace {

// The recorder and the renderer read the layer as the world's floor layer
// (framework/floor_layer.h): its area, size and the pixels painted.
TEST(PaintLayerTest, IsTheWorldsFloorLayer) {
  Fixture f(1, Area());
  const FloorLayer* floor = f.world->floor_layer();
  ASSERT_EQ(floor, static_cast<const FloorLayer*>(f.layer));
  PaintNozzleData nozzle;
  nozzle.radius = 0.05;
  nozzle.color = {1, 0, 0};
  f.AddRobot(0, nozzle);
  f.world->Start();
  f.world->Step();
  const FloorArea area = floor->floor_area();
  EXPECT_EQ(area.width, 100);
  EXPECT_EQ(area.height, 50);
  EXPECT_DOUBLE_EQ(area.min_x, -0.5);
  EXPECT_DOUBLE_EQ(area.max_y, 0.25);
  EXPECT_DOUBLE_EQ(area.resolution, 0.01);
  ASSERT_EQ(floor->floor_rgb().size(), f.layer->rgb().size());
  EXPECT_TRUE(
      std::equal(floor->floor_rgb().begin(), floor->floor_rgb().end(), f.layer->rgb().begin()));
  // The pixel under the nozzle (x = y = 0: column 50, row 25) is marked and red.
  EXPECT_TRUE(floor->floor_marked(50, 25));
  EXPECT_EQ(floor->floor_rgb()[3 * (25 * 100 + 50)], 255);
  EXPECT_FALSE(floor->floor_marked(0, 0));
}

}  // namespace
}  // namespace swarmsim::paint
