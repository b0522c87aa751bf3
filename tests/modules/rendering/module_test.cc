// The rendering module (modules/rendering/module.cc): vision sensors
// rendered at the start and then at their rate in the sense phase, what a
// sensor sees of the scene, the arena's top-down view framing every shape,
// and the view of a camera or vision sensor found by path.
#include "modules/rendering/module.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modules/rendering/objects.h"
#include "modules/rendering/render.h"
#include "tests/modules/module_world.h"

namespace swarmsim::rendering {
namespace {

using testing::ModuleWorld;

// A red 0.5 m cube at (1, 0) and a vision sensor at the origin looking at
// it along +x, 32x24 pixels, at `rate` Hz (0: every step).
struct Looking {
  ModuleWorld w;
  ObjectId cube, sensor;
  explicit Looking(double rate = 0) {
    ShapeData s;
    s.kind = ShapeKind::kBox;
    s.size = {0.5, 0.5, 0.5};
    s.color = {1, 0, 0};
    cube = w.scene().AddShape("cube", {}, {{1, 0, 0.25}, {}}, s);
    VisionSensorRow row;
    row.lens.width = 32;
    row.lens.height = 24;
    row.rate = rate;
    row.floor = false;
    row.background = {0, 0, 1};
    sensor = w.Add("vision_sensor", "eye", {}, {{0, 0, 0.25}, {}}, &row);
  }
  VisionSensorRow& row() { return w.RowOf<VisionSensorRow>("vision_sensor", sensor); }
};

TEST(RenderingModuleTest, AVisionSensorSeesTheSceneFromTheStart) {
  Looking l;
  ASSERT_EQ(l.w.Run(0), "");
  const VisionSensorRow& row = l.row();
  EXPECT_EQ(row.rendered_step, 0);
  ASSERT_EQ(row.image.width, 32);
  ASSERT_EQ(row.image.height, 24);
  const uint8_t* ahead = row.image.Pixel(16, 12);
  EXPECT_GT(ahead[0], 2 * ahead[2]);          // the red cube
  EXPECT_EQ(row.image.Pixel(16, 0)[2], 255);  // above it, the background
  ASSERT_EQ(row.image.depth.size(), 32u * 24u);
  EXPECT_NEAR(row.image.depth[12 * 32 + 16], 0.75, 1e-2);  // the cube's face, 1 - 0.25 m away
}

// At 2.5 Hz with steps of 0.1 s: an image every 4 steps.
TEST(RenderingModuleTest, ASensorRendersAtItsRate) {
  Looking l(2.5);
  ASSERT_EQ(l.w.Run(0), "");
  std::vector<int64_t> rendered;
  for (int i = 0; i < 9; ++i) {
    ASSERT_EQ(l.w.Run(1), "");
    rendered.push_back(l.row().rendered_step);
  }
  EXPECT_EQ(rendered.front(), 0);
  EXPECT_EQ(rendered.back(), 8);
  int changes = 0;
  for (size_t i = 1; i < rendered.size(); ++i) changes += rendered[i] != rendered[i - 1];
  EXPECT_EQ(changes, 2);
}

TEST(RenderingModuleTest, TheArenaViewLooksDownOnEveryShape) {
  ModuleWorld w;
  w.Box("a", {}, {{-2, -1, 0.5}, {}}, {1, 1, 1});
  w.Box("b", {}, {{4, 3, 0.5}, {}}, {1, 1, 1});
  ASSERT_EQ(w.Run(0), "");
  const View v = ArenaView(w.world(), 400, 200);
  EXPECT_TRUE(v.orthographic);
  EXPECT_EQ(v.width, 400);
  // The shapes span x -2.5..4.5 and y -1.5..3.5; centred above them.
  EXPECT_NEAR(v.pose.p.x, 1, 1e-9);
  EXPECT_NEAR(v.pose.p.y, 1, 1e-9);
  EXPECT_GT(v.pose.p.z, 1);
  // Looking down: the view's +x is the world's -z, its image up the world's +y.
  const Vec3 forward = v.pose.q.Rotate({1, 0, 0});
  EXPECT_NEAR(forward.z, -1, 1e-9);
  EXPECT_NEAR(v.pose.q.Rotate({0, 0, 1}).y, 1, 1e-9);
  // Wide enough for both extents (with a 5 % margin) at 2:1.
  const double margin = 0.05 * 7;
  EXPECT_NEAR(v.ortho_width, std::max(7 + 2 * margin, (5 + 2 * margin) * 2), 1e-9);
  // An empty scene: a 2 m square about the origin.
  ModuleWorld empty;
  ASSERT_EQ(empty.Run(0), "");
  const View e = ArenaView(empty.world(), 100, 100);
  EXPECT_NEAR(e.pose.p.x, 0, 1e-12);
  EXPECT_NEAR(e.ortho_width, 2.2, 1e-12);
}

TEST(RenderingModuleTest, ACameraViewIsFoundByPathOrSaysWhyNot) {
  Looking l;
  CameraRow camera;
  camera.lens.width = 320;
  camera.lens.height = 200;
  l.w.Add("camera", "overview", {}, {{0, 0, 5}, {}}, &camera);
  ASSERT_EQ(l.w.Run(0), "");
  std::string error;
  const auto view = CameraView(l.w.world(), "/overview", &error);
  ASSERT_TRUE(view.has_value()) << error;
  EXPECT_EQ(view->width, 320);
  EXPECT_NEAR(view->pose.p.z, 5, 1e-12);
  const auto eye = CameraView(l.w.world(), "/eye", &error);
  ASSERT_TRUE(eye.has_value()) << error;
  EXPECT_EQ(eye->width, 32);
  EXPECT_FALSE(CameraView(l.w.world(), "/cube", &error).has_value());
  EXPECT_EQ(error, "'/cube' is a shape, not a camera or vision sensor");
  EXPECT_FALSE(CameraView(l.w.world(), "/nowhere", &error).has_value());
  EXPECT_FALSE(error.empty());
}

}  // namespace
}  // namespace swarmsim::rendering
