// Drawing a draw list from a viewpoint (modules/rendering/render.cc,
// OSMesa): the background where nothing is, a shape in its colour where it
// is, depths along the view axis, hidden slots left out, images of any
// size refused past 8192, and the same bytes on any thread.
#include "modules/rendering/render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "framework/image.h"
#include "modules/rendering/geometry.h"
#include "tests/modules/module_world.h"

namespace swarmsim::rendering {
namespace {

using testing::ErrorOf;
using testing::ModuleWorld;

// A red 0.5 m cube standing at the origin (top at z = 0.5) and a green one
// at (3, 3) outside the view; drawn from 3 m up, looking down, 2 m across.
struct Cubes {
  ModuleWorld w;
  ObjectId red, green;
  DrawList list;
  Cubes() {
    ShapeData cube;
    cube.kind = ShapeKind::kBox;
    cube.size = {0.5, 0.5, 0.5};
    cube.color = {1, 0, 0};
    red = w.scene().AddShape("red", {}, {{0, 0, 0.25}, {}}, cube);
    cube.color = {0, 1, 0};
    green = w.scene().AddShape("green", {}, {{3, 3, 0.25}, {}}, cube);
    EXPECT_EQ(w.Run(0), "");
    BuildDrawList(w.world(), 16, &list);
  }
  static View Above() {
    View v;
    v.orthographic = true;
    v.ortho_width = 2;
    v.width = v.height = 64;
    v.near = 0.01;
    v.far = 10;
    v.depth = true;
    // Looking down (+x to -z), image up = +y.
    v.pose = {{0, 0, 3}, Quat::FromYaw(M_PI / 2) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)};
    return v;
  }
};

DrawOptions Plain() {
  DrawOptions o;
  o.floor = false;
  o.background = {0, 0, 1};
  return o;
}

TEST(RenderTest, AShapeIsDrawnInItsColourAndTheRestIsBackground) {
  Cubes s;
  Image image;
  Draw(s.list, Cubes::Above(), Plain(), &image);
  ASSERT_EQ(image.width, 64);
  ASSERT_EQ(image.height, 64);
  const uint8_t* centre = image.Pixel(32, 32);
  EXPECT_GT(centre[0], 60);
  EXPECT_GT(centre[0], 2 * centre[1]);
  EXPECT_GT(centre[0], 2 * centre[2]);
  // The cube spans 16 pixels of 64 (0.5 of 2 m); a corner is background.
  const uint8_t* corner = image.Pixel(2, 2);
  EXPECT_EQ(corner[0], 0);
  EXPECT_EQ(corner[1], 0);
  EXPECT_EQ(corner[2], 255);
  int red = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) red += image.Pixel(x, y)[2] != 255;
  EXPECT_NEAR(red, 16 * 16, 2 * 16 + 1);  // up to a pixel row of rounding on each side
}

TEST(RenderTest, DepthsAreAlongTheViewAxisAndFarWhereNothingIs) {
  Cubes s;
  Image image;
  Draw(s.list, Cubes::Above(), Plain(), &image);
  ASSERT_EQ(image.depth.size(), 64u * 64u);
  EXPECT_NEAR(image.depth[32 * 64 + 32], 2.5, 1e-3);  // the cube's top, 3 - 0.5 m away
  EXPECT_FLOAT_EQ(image.depth[2 * 64 + 2], 10);       // nothing: the far plane
  View no_depth = Cubes::Above();
  no_depth.depth = false;
  Draw(s.list, no_depth, Plain(), &image);
  EXPECT_TRUE(image.depth.empty());
}

TEST(RenderTest, SlotsMarkedInvisibleAreNotDrawn) {
  Cubes s;
  std::vector<uint8_t> visible(s.w.scene().slot_count(), 1);
  visible[s.w.scene().SlotOf(s.red)] = 0;
  DrawOptions options = Plain();
  options.visible = &visible;
  Image image;
  Draw(s.list, Cubes::Above(), options, &image);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) ASSERT_EQ(image.Pixel(x, y)[2], 255) << x << ", " << y;
}

// A perspective view from the side, along +x at the cube's mid-height.
TEST(RenderTest, APerspectiveViewSeesTheCubeAhead) {
  Cubes s;
  View side;
  side.pose = {{-3, 0, 0.25}, {}};
  side.width = 80;
  side.height = 60;
  Image image;
  Draw(s.list, side, Plain(), &image);
  const uint8_t* ahead = image.Pixel(40, 30);
  EXPECT_GT(ahead[0], 2 * ahead[2]);
  const uint8_t* above = image.Pixel(40, 2);
  EXPECT_EQ(above[2], 255);
  // Turned away, nothing.
  side.pose.q = Quat::FromYaw(M_PI);
  Draw(s.list, side, Plain(), &image);
  EXPECT_EQ(image.Pixel(40, 30)[2], 255);
}

TEST(RenderTest, TheSameListGivesTheSameBytesOnAnotherThread) {
  Cubes s;
  View v = Cubes::Above();
  v.depth = false;
  Image here, there;
  Draw(s.list, v, DrawOptions{}, &here);
  std::thread([&] { Draw(s.list, v, DrawOptions{}, &there); }).join();
  EXPECT_EQ(here.rgb, there.rgb);
}

// A white wall 10 m wide, its face 1 m ahead of the eye, lit by one light
// the test places (the ambient term is 0.2: 51 of 255).
struct LitWall {
  ModuleWorld w;
  DrawList list;
  LitWall() {
    ShapeData wall;
    wall.kind = ShapeKind::kBox;
    wall.size = {0.2, 10, 10};
    wall.color = {1, 1, 1};
    w.scene().AddShape("wall", {}, {{1.1, 0, 0.5}, {}}, wall);
    EXPECT_EQ(w.Run(0), "");
    BuildDrawList(w.world(), 16, &list);
    list.scene_has_lights = true;
  }
  int Red(const LightSource& light, int x, int y) {
    list.lights = {light};
    View eye;  // along +x, 60 degrees across
    eye.pose = {{0, 0, 0.5}, {}};
    eye.width = eye.height = 9;
    Image image;
    Draw(list, eye, Plain(), &image);
    return image.Pixel(x, y)[0];
  }
};

// Point and spot lights are lit per pixel: a spot aimed at the middle of a
// wall much larger than its cone lit no vertex of it, so per vertex the
// middle stayed at the ambient level (QA: 51 where the cone falls).
TEST(RenderTest, ASpotLightsWhereItsConeFallsOnALargeFace) {
  LitWall s;
  LightSource spot;
  spot.kind = LightSource::kSpot;
  spot.position = {0, 0, 0.5};
  spot.direction = {1, 0, 0};
  spot.cutoff = 15 * M_PI / 180;
  EXPECT_EQ(s.Red(spot, 4, 4), 255) << "on the axis: 0.2 + cos 0, capped";
  EXPECT_EQ(s.Red(spot, 0, 4), 51) << "27 degrees off the axis: outside the cone, ambient";
}

TEST(RenderTest, APointLightOnALargeFaceFollowsLambertsLaw) {
  LitWall s;
  LightSource point;
  point.kind = LightSource::kPoint;
  point.position = {0.5, 0.5, 0.5};  // 45 degrees off the middle's normal
  EXPECT_NEAR(s.Red(point, 4, 4), 255 * (0.2 + M_SQRT1_2), 2);  // was 76
}

TEST(RenderTest, AnImageTooLargeIsRefused) {
  Cubes s;
  View v = Cubes::Above();
  v.width = 9000;
  Image image;
  EXPECT_EQ(ErrorOf([&] { Draw(s.list, v, Plain(), &image); }),
            "image size 9000x64 is outside 1..8192 pixels a side");
}

}  // namespace
}  // namespace swarmsim::rendering
