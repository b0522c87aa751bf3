// The built-in filter elements (filters/elements.cc) on synthetic images:
// HSV and colour thresholds, exact grayscale and resize, Sobel edges of a
// square, the point cloud of a flat depth image, the depth threshold; and
// worlds/README.md documents every element and key.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "framework/error.h"
#include "framework/plugin_loader.h"
#include "framework/registry.h"
#include "framework/vision_filter.h"
#include "modules/builtin.h"
#include "modules/rendering/filters/filters.h"
#include "tests/framework/error_of.h"
#include "tests/modules/rendering/filters/filter_list_reader.h"
#include "tests/modules/rendering/filters/test_images.h"

namespace swarmsim::filters {
namespace {

using testing::FilterItem;
using testing::FilterListReader;

constexpr double kDeg = M_PI / 180;

FilterChain Chain(std::vector<FilterItem> items, const ModuleRegistry* registry = nullptr) {
  return ParseFilterChain(FilterListReader(std::move(items), registry), "filters", registry);
}

using swarmsim::testing::Filled;

TEST(VisionFiltersTest, HsvThresholdPicksThePixelsInItsRanges) {
  // One pixel per colour: which hsv_threshold keeps (green hue, saturated, bright).
  struct Case {
    uint8_t rgb[3];
    bool green, red;
  };
  const Case cases[] = {
      {{0, 255, 0}, true, false},       // hue 120
      {{40, 200, 90}, true, false},     // hue ~139
      {{255, 255, 0}, false, false},    // yellow, hue 60
      {{0, 255, 255}, false, false},    // cyan, hue 180
      {{0, 60, 0}, false, false},       // dark green: value 0.24
      {{150, 200, 150}, false, false},  // pale green: saturation 0.25
      {{255, 0, 0}, false, true},       // hue 0
      {{255, 0, 40}, false, true},      // hue ~351
      {{255, 60, 0}, false, true},      // hue ~14
      {{128, 128, 128}, false, false},  // grey
      {{0, 0, 0}, false, false},        // black: saturation 0, not 1
  };
  const int n = static_cast<int>(std::size(cases));
  Image image;
  image.Resize(n, 1);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) image.Pixel(i, 0)[c] = cases[i].rgb[c];
  const FilterOutput green =
      Chain(
          {{"hsv_threshold", {{"hue", {100, 140}}, {"saturation", {0.5, 1}}, {"value", {0.3, 1}}}}})
          .Run(image, {});
  const FilterOutput red =
      Chain({{"hsv_threshold", {{"hue", {340, 20}}, {"saturation", {0.5, 1}}}}}).Run(image, {});
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(green.image.Pixel(i, 0)[0], cases[i].green ? 255 : 0) << i;
    EXPECT_EQ(red.image.Pixel(i, 0)[0], cases[i].red ? 255 : 0) << i;
  }
}

TEST(VisionFiltersTest, ColorThresholdKeepsPixelsWithinToleranceInEveryChannel) {
  Image image;
  image.Resize(4, 1);
  const uint8_t pixels[4][3] = {{100, 100, 100}, {125, 100, 100}, {126, 100, 100}, {100, 80, 120}};
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < 3; ++c) image.Pixel(i, 0)[c] = pixels[i][c];
  // 0.1 tolerance = 25.5 levels.
  const FilterOutput out =
      Chain({{"color_threshold",
              {{"color", {100 / 255.0, 100 / 255.0, 100 / 255.0}}, {"tolerance", {0.1}}}}})
          .Run(image, {});
  EXPECT_EQ(out.image.Pixel(0, 0)[0], 255);
  EXPECT_EQ(out.image.Pixel(1, 0)[0], 255);
  EXPECT_EQ(out.image.Pixel(2, 0)[0], 0);
  EXPECT_EQ(out.image.Pixel(3, 0)[0], 255);
}

TEST(VisionFiltersTest, GrayscaleAndResizeAreExactOnSimpleImages) {
  Image image;
  image.Resize(4, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      uint8_t* p = image.Pixel(x, y);
      p[0] = static_cast<uint8_t>(10 * x), p[1] = static_cast<uint8_t>(100 + 10 * y), p[2] = 40;
    }
  const FilterOutput grey = Chain({{"grayscale", {}}}).Run(image, {});
  ASSERT_EQ(grey.image.width, 4);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      const int mean = (10 * x + 100 + 10 * y + 40 + 1) / 3;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(grey.image.Pixel(x, y)[c], mean) << x << "," << y;
    }
  // Halving: each output pixel is the mean of a 2x2 cell (rounded).
  const FilterOutput half = Chain({{"resize", {{"width", {2}}, {"height", {1}}}}}).Run(image, {});
  ASSERT_EQ(half.image.width, 2);
  ASSERT_EQ(half.image.height, 1);
  EXPECT_EQ(half.image.Pixel(0, 0)[0], 5);    // (0 + 10 + 0 + 10) / 4
  EXPECT_EQ(half.image.Pixel(1, 0)[0], 25);   // (20 + 30) / 2
  EXPECT_EQ(half.image.Pixel(0, 0)[1], 105);  // (100 + 110) / 2
  // Doubling: each source pixel becomes a 2x2 cell.
  const FilterOutput twice = Chain({{"resize", {{"width", {8}}, {"height", {4}}}}}).Run(image, {});
  ASSERT_EQ(twice.image.width, 8);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(twice.image.Pixel(x, y)[c], image.Pixel(x / 2, y / 2)[c]);
  // A mask stays a mask: set where at least half its cell is.
  Image stripes = Filled(4, 1, 0, 0, 0);
  stripes.Pixel(0, 0)[0] = stripes.Pixel(0, 0)[1] = stripes.Pixel(0, 0)[2] = 255;
  const FilterOutput mask = Chain({{"color_threshold", {{"color", {1, 1, 1}}}},
                                   {"resize", {{"width", {2}}, {"height", {1}}}}})
                                .Run(stripes, {});
  EXPECT_EQ(mask.image.Pixel(0, 0)[0], 255);
  EXPECT_EQ(mask.image.Pixel(1, 0)[0], 0);
}

TEST(VisionFiltersTest, EdgesFindASquaresBorder) {
  Image image = Filled(32, 32, 0, 0, 0);
  for (int y = 10; y < 20; ++y)
    for (int x = 10; x < 20; ++x) image.Pixel(x, y)[0] = image.Pixel(x, y)[1] = 255;
  const FilterOutput out = Chain({{"edges", {{"threshold", {0.2}}}}}).Run(image, {});
  // The band one pixel either side of the border, nothing inside or outside it.
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const bool outer = x >= 9 && x <= 20 && y >= 9 && y <= 20;
      const bool inner = x >= 11 && x <= 18 && y >= 11 && y <= 18;
      EXPECT_EQ(out.image.Pixel(x, y)[0], outer && !inner ? 255 : 0) << x << "," << y;
    }
  // Above the strongest gradient (a full step is 1; this one is 2/3): nothing.
  const FilterOutput none = Chain({{"edges", {{"threshold", {0.9}}}}}).Run(image, {});
  for (size_t i = 0; i < none.image.rgb.size(); ++i) ASSERT_EQ(none.image.rgb[i], 0) << i;
}

TEST(VisionFiltersTest, PointCloudOfAFlatDepthImageLiesOnItsPlane) {
  Image image = Filled(32, 24, 0, 0, 0);
  image.depth.assign(32 * 24, 2.0f);
  for (int x = 0; x < 32; ++x) image.depth[static_cast<size_t>(23) * 32 + x] = 10.0f;  // far
  CameraModel camera;
  camera.fov = 60 * kDeg;
  camera.near = 0.1;
  camera.far = 10;
  const FilterChain chain = Chain({{"depth", {}}, {"point_cloud", {}}});
  EXPECT_TRUE(chain.needs_depth());
  const FilterOutput out = chain.Run(image, camera);
  ASSERT_EQ(out.points.size(), 32u * 23u);                    // not the far row
  const double pitch = 2 * std::tan(30 * kDeg) / 32;          // m per pixel at 1 m, larger side
  for (const Vec3& p : out.points) EXPECT_DOUBLE_EQ(p.x, 2);  // along the view axis
  // First point: the top-left pixel, to the left (+y) and up (+z).
  EXPECT_NEAR(out.points[0].y, 15.5 * pitch * 2, 1e-12);
  EXPECT_NEAR(out.points[0].z, 11.5 * pitch * 2, 1e-12);
  // The image's edges at 2 m span the view angle.
  EXPECT_NEAR(out.points[31].y - out.points[0].y, -31 * pitch * 2, 1e-12);
  EXPECT_TRUE(out.triggered);
  ASSERT_EQ(out.packets.size(), 2u);
  EXPECT_EQ(out.packets[1][0], 32 * 23);
  EXPECT_EQ(out.packets[1][1], 2);  // the first point's x: its depth
  // A blob's bearing from its centroid: the same rays.
  const Vec3 p = ImageToSensor(camera, 32, 24, 0.5, 0.5, 2);
  EXPECT_DOUBLE_EQ(p.y, out.points[0].y);
  EXPECT_DOUBLE_EQ(p.z, out.points[0].z);
  const Vec3 edge = ImageToSensor(camera, 32, 24, 32, 12, 1);  // right edge, middle row
  EXPECT_NEAR(std::atan2(edge.y, edge.x), -30 * kDeg, 1e-12);
  // Orthographic: pixel pitch ortho_size / larger side whatever the depth.
  camera.perspective = false;
  camera.ortho_size = 3.2;
  const FilterOutput ortho =
      Chain({{"depth", {}}, {"point_cloud", {{"stride", {2}}}}}).Run(image, camera);
  ASSERT_EQ(ortho.points.size(), 16u * 12u);
  EXPECT_NEAR(ortho.points[0].y, 15.5 * 0.1, 1e-12);
  EXPECT_NEAR(ortho.points[1].y, 13.5 * 0.1, 1e-12);
}

TEST(VisionFiltersTest, DepthThresholdMasksTheNearPixels) {
  Image image = Filled(4, 1, 0, 0, 0);
  image.depth = {0.5f, 1.0f, 1.5f, 3.0f};
  const FilterOutput out =
      Chain({{"depth", {}}, {"depth_threshold", {{"range", {0.8, 1.6}}}}, {"blobs", {}}})
          .Run(image, {});
  ASSERT_EQ(out.blobs.size(), 1u);
  EXPECT_EQ(out.blobs[0].pixels, 2);
  EXPECT_EQ(out.blobs[0].min_x, 1);
  // Resized depth is the mean of each cell: 0.75 and 2.25, only the first kept.
  const FilterOutput half = Chain({{"depth", {}},
                                   {"resize", {{"width", {2}}, {"height", {1}}}},
                                   {"depth_threshold", {{"range", {0.7, 0.8}}}},
                                   {"blobs", {}}})
                                .Run(image, {});
  ASSERT_EQ(half.blobs.size(), 1u);
  EXPECT_EQ(half.blobs[0].min_x, 0);
  EXPECT_EQ(half.blobs[0].max_x, 0);
}

}  // namespace
}  // namespace swarmsim::filters

namespace swarmsim::filters {
namespace {

// worlds/README.md's "vision sensor filters" lists every built-in element
// and each of its keys.
TEST(VisionFiltersTest, WorldsReadmeDocumentsEveryElementAndKey) {
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/README.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string readme = text.str();
  const size_t start = readme.find("\n#### vision sensor filters\n");
  ASSERT_NE(start, std::string::npos);
  const std::string section = readme.substr(start, readme.find("\n## ", start) - start);
  ModuleRegistry registry;
  Register(&registry);
  ASSERT_GE(registry.vision_filters().size(), 10u);
  for (const auto& d : registry.vision_filters()) {
    EXPECT_NE(section.find("| `" + d->name + "` |"), std::string::npos) << d->name;
    for (const VisionFilterKey& key : d->keys)
      EXPECT_NE(
          section.find("| `" + d->name + "` | `" + key.name + "` | " + key.default_text + " |"),
          std::string::npos)
          << d->name << "." << key.name;
  }
}

}  // namespace
}  // namespace swarmsim::filters
