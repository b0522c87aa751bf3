// The video's trimmed draw lists (modules/rendering/video/frame_geometry.h):
// dropping the faces a view cannot see leaves the picture as it was.
#include "modules/rendering/video/frame_geometry.h"

#include <gtest/gtest.h>

#include <cmath>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/rendering/render.h"

namespace swarmsim {
namespace {

ShapeData Shape(ShapeKind kind, const Vec3& size, const Vec3& color) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  s.color = color;
  return s;
}

// Boxes, cylinders (upright and lying like wheels), a sphere and a capsule,
// turned every which way.
class FrameGeometryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RegisterBuiltinModules(&registry_);
    WorldSettings settings;
    settings.physics = "kinematic";
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([](std::string_view) {});
    Scene& scene = world_->scene();
    const Quat tilted = Quat::FromAxisAngle(Vec3{1, 2, 0.5}.Normalized(), 0.7);
    scene.AddShape("box", {}, {{0.4, 0.3, 0.2}, tilted},
                   Shape(ShapeKind::kBox, {0.3, 0.2, 0.25}, {0.9, 0.1, 0.1}));
    scene.AddShape("body", {}, {{-0.4, -0.2, 0.08}, Quat::FromYaw(0.3)},
                   Shape(ShapeKind::kCylinder, {0.085, 0.085, 0.146}, {0.1, 0.8, 0.1}));
    scene.AddShape("wheel", {}, {{-0.4, 0.4, 0.03}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)},
                   Shape(ShapeKind::kCylinder, {0.03, 0.03, 0.02}, {0.2, 0.2, 0.2}));
    scene.AddShape("ball", {}, {{0.3, -0.4, 0.1}, tilted},
                   Shape(ShapeKind::kSphere, {0.1, 0.1, 0.1}, {0.1, 0.1, 0.9}));
    scene.AddShape("pill", {}, {{0, 0, 0.1}, tilted},
                   Shape(ShapeKind::kCapsule, {0.05, 0.05, 0.3}, {0.9, 0.8, 0.1}));
    world_->Start();
  }

  // The image of the full list and of the trimmed one, and the triangles of each.
  void Compare(const rendering::View& view, int segments) {
    rendering::DrawList full, trimmed;
    rendering::BuildDrawList(*world_, segments, &full);
    rendering::BuildDrawList(*world_, segments, &trimmed);
    std::vector<uint8_t> closed;
    video::MarkClosed(world_->scene(), trimmed, &closed);
    video::DropHiddenFaces(view, closed, &trimmed);
    EXPECT_LT(trimmed.xyz.size(), full.xyz.size() * 2 / 3) << "most hidden faces dropped";
    Image a, b;
    rendering::Draw(full, view, rendering::DrawOptions{}, &a);
    rendering::Draw(trimmed, view, rendering::DrawOptions{}, &b);
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    // The same picture, but for a few pixels on silhouettes, where a face
    // turned away shares an edge with one in front and may win its pixel.
    int differ = 0, drawn = 0;  // drawn: unlike the top-left corner
    for (size_t p = 0; p < a.rgb.size(); p += 3) {
      differ +=
          a.rgb[p] != b.rgb[p] || a.rgb[p + 1] != b.rgb[p + 1] || a.rgb[p + 2] != b.rgb[p + 2];
      drawn += a.rgb[p] != a.rgb[0] || a.rgb[p + 1] != a.rgb[1] || a.rgb[p + 2] != a.rgb[2];
    }
    EXPECT_GT(drawn, 1000) << "the shapes are in view";
    EXPECT_LE(differ, 10) << "of " << drawn << " pixels";
  }

  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
};

TEST_F(FrameGeometryTest, TheArenaFromAboveLooksTheSameWithoutHiddenFaces) {
  const rendering::View view = rendering::ArenaView(*world_, 320, 240);
  Compare(view, video::SegmentsFor(view));
}

TEST_F(FrameGeometryTest, AnObliqueCameraLooksTheSameWithoutHiddenFaces) {
  rendering::View view;
  view.width = 320;
  view.height = 240;
  view.pose.p = {-1.5, -1.2, 1.0};
  // Looking at the origin: yaw toward it, pitched down.
  view.pose.q = Quat::FromYaw(std::atan2(1.2, 1.5)) * Quat::FromAxisAngle({0, 1, 0}, 0.45);
  Compare(view, video::SegmentsFor(view));
}

TEST_F(FrameGeometryTest, SidesFollowTheSizeOfARobotInPixels) {
  rendering::View view;
  view.orthographic = true;
  view.width = 640;
  view.ortho_width = 35;  // a thousand robots' arena
  EXPECT_EQ(video::SegmentsFor(view), 6);
  view.ortho_width = 3;  // a robot 43 pixels across
  EXPECT_GT(video::SegmentsFor(view), 8);
  view.orthographic = false;
  EXPECT_EQ(video::SegmentsFor(view), 16);
}

}  // namespace
}  // namespace swarmsim
