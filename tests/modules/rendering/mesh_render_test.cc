// Meshes in rendered images (modules/rendering: vision sensors, and the
// snapshots and video of `swarmsim run --snapshot-every, --video`): a mesh
// shape is drawn as its triangles, not its bounding box, in its colour or
// in its own per-triangle colours.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "framework/image.h"
#include "framework/mesh.h"
#include "modules/paint/png_io.h"
#include "modules/rendering/geometry.h"
#include "modules/rendering/render.h"
#include "modules/rendering/video/recorder.h"
#include "tests/modules/module_world.h"

namespace swarmsim::rendering {
namespace {

using testing::ModuleWorld;
using testing::TempDir;

// A right-triangular prism 0.1 m thick: its top face the triangle
// (-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5) at z = 0.1, its bottom at z = 0,
// closed, counter-clockwise seen from outside. From above it covers half of
// its bounding box (the square [-0.5, 0.5]^2): the half below the diagonal
// x + y = 0.
std::shared_ptr<const TriangleMesh> Prism(std::vector<Vec3> colors = {}) {
  const std::vector<Vec3> v = {{-0.5, -0.5, 0},   {0.5, -0.5, 0},   {-0.5, 0.5, 0},
                               {-0.5, -0.5, 0.1}, {0.5, -0.5, 0.1}, {-0.5, 0.5, 0.1}};
  const std::vector<MeshTriangle> t = {{{3, 4, 5}}, {{0, 2, 1}},   // top, bottom
                                       {{0, 1, 4}}, {{0, 4, 3}},   // y = -0.5
                                       {{0, 3, 5}}, {{0, 5, 2}},   // x = -0.5
                                       {{1, 2, 5}}, {{1, 5, 4}}};  // the diagonal side
  if (!colors.empty()) colors.resize(t.size(), colors.back());
  return std::make_shared<TriangleMesh>("prism", v, t, colors);
}

ShapeData MeshShape(std::shared_ptr<const TriangleMesh> mesh, const Vec3& color, bool own) {
  ShapeData s;
  s.kind = ShapeKind::kMesh;
  s.mesh = std::move(mesh);
  s.size = s.mesh->CenteredExtents();
  s.color = color;
  s.mesh_colors = own;
  return s;
}

// Looking down from 3 m on a 2 m square, 64 pixels: world (x, y) is pixel
// (32 + 32 x, 32 - 32 y).
View Above() {
  View v;
  v.orthographic = true;
  v.ortho_width = 2;
  v.width = v.height = 64;
  v.near = 0.01;
  v.far = 10;
  v.pose = {{0, 0, 3}, Quat::FromYaw(M_PI / 2) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)};
  return v;
}
const uint8_t* At(const Image& image, double x, double y) {
  return image.Pixel(static_cast<int>(32 + 32 * x), static_cast<int>(32 - 32 * y));
}
bool IsRed(const uint8_t* c) { return c[0] > 60 && c[0] > 2 * c[1] && c[0] > 2 * c[2]; }
bool IsGreen(const uint8_t* c) { return c[1] > 60 && c[1] > 2 * c[0] && c[1] > 2 * c[2]; }
bool IsBackground(const uint8_t* c) { return c[0] == 0 && c[1] == 0 && c[2] == 255; }

Image Draw(const World& world) {
  DrawList list;
  BuildDrawList(world, 16, &list);
  DrawOptions options;
  options.floor = false;
  options.background = {0, 0, 1};
  Image image;
  Draw(list, Above(), options, &image);
  return image;
}

TEST(MeshRenderTest, AMeshIsDrawnAsItsTrianglesNotItsBox) {
  ModuleWorld w;
  w.scene().AddShape("prism", {}, {}, MeshShape(Prism(), {1, 0, 0}, false));
  ASSERT_EQ(w.Run(0), "");
  const Image image = Draw(w.world());
  // Below the diagonal: the prism; above it, inside the box: nothing.
  for (const auto& [x, y] : {std::pair{-0.3, -0.3}, {0.3, -0.4}, {-0.4, 0.3}})
    EXPECT_TRUE(IsRed(At(image, x, y))) << x << ", " << y;
  for (const auto& [x, y] : {std::pair{0.3, 0.3}, {0.4, 0.0}, {0.0, 0.4}})
    EXPECT_TRUE(IsBackground(At(image, x, y))) << x << ", " << y;
  // Half the box's 32 x 32 pixels, to a row of pixels along the edges.
  int drawn = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) drawn += !IsBackground(image.Pixel(x, y));
  EXPECT_NEAR(drawn, 32 * 32 / 2, 3 * 32);
}

TEST(MeshRenderTest, AMeshInItsOwnColoursShowsThemAndNotTheShapesColour) {
  // The top face red, every other face green; the shape's own colour blue-ish
  // grey is not used while it draws its mesh's colours.
  ModuleWorld w;
  const ObjectId prism = w.scene().AddShape(
      "prism", {}, {}, MeshShape(Prism({{1, 0, 0}, {0, 1, 0}}), {0.3, 0.3, 0.6}, true));
  ASSERT_EQ(w.Run(0), "");
  const Image top = Draw(w.world());
  EXPECT_TRUE(IsRed(At(top, -0.3, -0.3)));
  // Turned upside down (about x), its bottom face shows: green.
  w.scene().SetLocalPose(prism, {{0, 0, 0.1}, Quat::FromAxisAngle({1, 0, 0}, M_PI)});
  ASSERT_EQ(w.Run(1), "");
  const Image bottom = Draw(w.world());
  // Turned, it covers the half above the other diagonal (y >= x).
  EXPECT_TRUE(IsGreen(At(bottom, -0.3, 0.3)));
  EXPECT_TRUE(IsBackground(At(bottom, 0.3, -0.3)));
}

// Snapshots (`swarmsim run --snapshot-every`) go through the same drawing:
// the prism covers about half the pixels its bounding box, drawn as a box
// shape in the same place, covers.
TEST(MeshRenderTest, SnapshotsDrawTheMeshNotItsBox) {
  const auto coloured = [](const ShapeData& shape) {
    TempDir dir;
    ModuleWorld w;
    w.scene().AddShape("part", {}, {}, shape);
    w.Box("far", {}, {{3, 3, 0.05}, {}}, {0.1, 0.1, 0.1});  // the view frames both
    video::RecorderSettings settings;
    settings.out_dir = dir.path();
    settings.snapshot_every = 1;
    settings.width = 200;
    settings.height = 200;
    w.world().AddModule("recorder", &settings);
    EXPECT_EQ(w.Run(1), "");
    w.world().WriteOutputs(settings.out_dir);
    const paint::RgbImage png = paint::ReadPng(dir.path() / "snapshots/step_000000.png");
    int red = 0;
    for (size_t i = 0; i + 2 < png.rgb.size(); i += 3)
      red += png.rgb[i] > 120 && png.rgb[i] > 2 * png.rgb[i + 1] && png.rgb[i] > 2 * png.rgb[i + 2];
    return red;
  };
  const int mesh = coloured(MeshShape(Prism(), {1, 0, 0}, false));
  ShapeData box;
  box.kind = ShapeKind::kBox;
  box.size = Prism()->CenteredExtents();
  box.color = {1, 0, 0};
  const int as_box = coloured(box);
  ASSERT_GT(as_box, 100);
  EXPECT_NEAR(static_cast<double>(mesh) / as_box, 0.5, 0.12) << mesh << " of " << as_box;
}

}  // namespace
}  // namespace swarmsim::rendering
