// Vision-sensor filter chains (modules/rendering/filters) on synthetic
// images: blobs of drawn discs and ellipses, HSV and colour thresholds,
// exact grayscale and resize, Sobel edges of a square, the point cloud of a
// flat depth image, the statistics packet, chain typing, the example
// plugin's elements, and a chain shared between threads.
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
#include "tests/modules/filter_list_reader.h"

namespace swarmsim::filters {
namespace {

using testing::FilterItem;
using testing::FilterListReader;

constexpr double kDeg = M_PI / 180;

FilterChain Chain(std::vector<FilterItem> items, const ModuleRegistry* registry = nullptr) {
  return ParseFilterChain(FilterListReader(std::move(items), registry), "filters", registry);
}

std::string ChainError(std::vector<FilterItem> items) {
  try {
    Chain(std::move(items));
  } catch (const Error& e) {
    return e.what();
  }
  return "NO ERROR";
}

Image Filled(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
  Image image;
  image.Resize(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = image.Pixel(x, y);
      p[0] = r, p[1] = g, p[2] = b;
    }
  return image;
}

// What the test drew of one shape: its pixels' count, mean centre and box.
struct Drawn {
  int pixels = 0;
  double x = 0, y = 0;  // mean pixel centre
  int min_x = 1 << 30, min_y = 1 << 30, max_x = -1, max_y = -1;
};

// An ellipse of semi-axes a (along angle `angle`, counter-clockwise with y
// up) and b, centred at (cx, cy) in pixels (y down), filled with `colour`.
Drawn DrawEllipse(Image* image, double cx, double cy, double a, double b, double angle,
                  const uint8_t colour[3]) {
  Drawn d;
  const double c = std::cos(angle), s = std::sin(angle);
  for (int y = 0; y < image->height; ++y)
    for (int x = 0; x < image->width; ++x) {
      const double dx = x + 0.5 - cx, dy_up = cy - (y + 0.5);
      const double along = dx * c + dy_up * s, across = -dx * s + dy_up * c;
      if (along * along / (a * a) + across * across / (b * b) > 1) continue;
      uint8_t* p = image->Pixel(x, y);
      p[0] = colour[0], p[1] = colour[1], p[2] = colour[2];
      ++d.pixels;
      d.x += x + 0.5;
      d.y += y + 0.5;
      d.min_x = std::min(d.min_x, x), d.max_x = std::max(d.max_x, x);
      d.min_y = std::min(d.min_y, y), d.max_y = std::max(d.max_y, y);
    }
  d.x /= d.pixels;
  d.y /= d.pixels;
  return d;
}

void ExpectBlobIs(const Blob& blob, const Drawn& drawn, const uint8_t colour[3], const Image& im) {
  EXPECT_EQ(blob.pixels, drawn.pixels);
  EXPECT_NEAR(blob.x, drawn.x, 1e-9);
  EXPECT_NEAR(blob.y, drawn.y, 1e-9);
  EXPECT_NEAR(blob.u, drawn.x / im.width, 1e-9);
  EXPECT_NEAR(blob.v, 1 - drawn.y / im.height, 1e-9);
  EXPECT_EQ(blob.min_x, drawn.min_x);
  EXPECT_EQ(blob.max_x, drawn.max_x);
  EXPECT_EQ(blob.min_y, drawn.min_y);
  EXPECT_EQ(blob.max_y, drawn.max_y);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(blob.colour[c], colour[c] / 255.0, 1e-12);
}

TEST(VisionFiltersTest, BlobsOfTwoDiscsHaveTheirSizeCentroidBoxAndColour) {
  Image image = Filled(64, 48, 90, 90, 90);  // grey: saturation 0
  const uint8_t red[3] = {220, 30, 20}, blue[3] = {20, 40, 200};
  const Drawn big = DrawEllipse(&image, 16.3, 20.1, 7, 7, 0, red);
  const Drawn small = DrawEllipse(&image, 45, 33.5, 4, 4, 0, blue);
  const FilterChain chain =
      Chain({{"hsv_threshold", {{"saturation", {0.5, 1}}}}, {"blobs", {{"min_pixels", {4}}}}});
  const FilterOutput out = chain.Run(image, CameraModel{});
  ASSERT_EQ(out.blobs.size(), 2u);
  ExpectBlobIs(out.blobs[0], big, red, image);  // largest first
  ExpectBlobIs(out.blobs[1], small, blue, image);
  EXPECT_TRUE(out.triggered);
  // Packets: the statistics, then blobs: count, 10 values per blob.
  ASSERT_EQ(out.packets.size(), 2u);
  EXPECT_EQ(out.packets[0].size(), 15u);
  EXPECT_EQ(out.packets[0][4], 1);  // no depth image: depth at the far plane
  const std::vector<double>& p = out.packets[1];
  ASSERT_EQ(p.size(), 2u + 2 * 10);
  EXPECT_EQ(p[0], 2);
  EXPECT_EQ(p[1], 10);
  EXPECT_DOUBLE_EQ(p[2], big.pixels / (64.0 * 48.0));
  EXPECT_DOUBLE_EQ(p[4], out.blobs[0].u);
  EXPECT_DOUBLE_EQ(p[5], out.blobs[0].v);
  EXPECT_DOUBLE_EQ(p[6], (big.max_x - big.min_x + 1) / 64.0);
  EXPECT_DOUBLE_EQ(p[11], big.pixels);
  EXPECT_DOUBLE_EQ(p[12 + 6], 20 / 255.0);  // the second blob's red and blue
  EXPECT_DOUBLE_EQ(p[12 + 8], 200 / 255.0);
  // The work image is the mask: white on the discs, black elsewhere.
  ASSERT_EQ(out.image.width, 64);
  EXPECT_EQ(out.image.Pixel(16, 20)[0], 255);
  EXPECT_EQ(out.image.Pixel(2, 2)[1], 0);
}

TEST(VisionFiltersTest, MinPixelsDropsSmallBlobsAndNothingFoundDoesNotTrigger) {
  Image image = Filled(32, 32, 0, 0, 0);
  const uint8_t white[3] = {255, 255, 255};
  DrawEllipse(&image, 8, 8, 1.2, 1.2, 0, white);  // a few pixels
  const Drawn big = DrawEllipse(&image, 20, 20, 5, 5, 0, white);
  const FilterChain chain =
      Chain({{"color_threshold", {{"color", {1, 1, 1}}}}, {"blobs", {{"min_pixels", {10}}}}});
  const FilterOutput out = chain.Run(image, {});
  ASSERT_EQ(out.blobs.size(), 1u);
  EXPECT_EQ(out.blobs[0].pixels, big.pixels);
  const FilterOutput none = chain.Run(Filled(32, 32, 0, 0, 0), {});
  EXPECT_TRUE(none.blobs.empty());
  EXPECT_FALSE(none.triggered);
  EXPECT_EQ(none.packets[1][0], 0);
}

TEST(VisionFiltersTest, BlobOrientationIsTheEllipsesMajorAxis) {
  const uint8_t green[3] = {0, 200, 0};
  for (double angle_deg : {0.0, 30.0, -45.0, 70.0, 90.0}) {
    Image image = Filled(64, 64, 0, 0, 0);
    DrawEllipse(&image, 32, 32, 20, 6, angle_deg * kDeg, green);
    const FilterOutput out =
        Chain({{"color_threshold", {{"color", {0, 200 / 255.0, 0}}, {"tolerance", {0.05}}}},
               {"blobs", {}}})
            .Run(image, {});
    ASSERT_EQ(out.blobs.size(), 1u);
    double got = out.blobs[0].orientation / kDeg;
    if (angle_deg == 90.0 && got < 0) got += 180;  // the axis, either way
    EXPECT_NEAR(got, angle_deg, 1.5) << angle_deg;
    EXPECT_EQ(out.packets[1][3], out.blobs[0].orientation);
  }
}

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

TEST(VisionFiltersTest, StatisticsPacketIsMinMaxMeanOfIntensityChannelsAndDepth) {
  Image image;
  image.Resize(2, 1);
  image.Pixel(0, 0)[0] = 0, image.Pixel(0, 0)[1] = 51, image.Pixel(0, 0)[2] = 0;
  image.Pixel(1, 0)[0] = 255, image.Pixel(1, 0)[1] = 102, image.Pixel(1, 0)[2] = 153;
  image.depth = {1.0f, 3.0f};
  CameraModel camera;
  camera.near = 1;
  camera.far = 5;
  const std::vector<double> p = FilterChain().Run(image, camera).packets.at(0);
  ASSERT_EQ(p.size(), 15u);
  const std::vector<double> expected = {51 / 765.0,
                                        0,
                                        0.2,
                                        0,
                                        0,  // min: intensity, r, g, b, depth
                                        1.0 * (255 + 102 + 153) / 765,
                                        1,
                                        0.4,
                                        0.6,
                                        0.5,  // max
                                        (51 + 510) / 765.0 / 2,
                                        0.5,
                                        0.3,
                                        0.3,
                                        0.25};  // mean
  for (size_t i = 0; i < 15; ++i) EXPECT_NEAR(p[i], expected[i], 1e-12) << i;
  // Left to the reader: the same numbers from ImageStatistics.
  FilterOutput later;
  Chain({{"grayscale", {}}}).Run(image, camera, &later, /*statistics=*/false);
  ASSERT_EQ(later.packets.size(), 1u);
  EXPECT_TRUE(later.packets[0].empty());
  EXPECT_EQ(ImageStatistics(image, camera), p);
  // An empty image: zeros, no element runs.
  const FilterOutput empty =
      Chain({{"resize", {{"width", {4}}, {"height", {4}}}}}).Run(Image{}, camera);
  EXPECT_EQ(empty.packets, std::vector<std::vector<double>>{std::vector<double>(15, 0.0)});
}

TEST(VisionFiltersTest, KindsThatDoNotFitAreErrorsNamingBothElements) {
  EXPECT_CONTAINS(ChainError({{"grayscale", {}}, {"blobs", {}}}),
                  "filters[1].type: 'blobs' needs a mask; 'grayscale' gives a grey image: put a "
                  "threshold before it");
  EXPECT_CONTAINS(ChainError({{"blobs", {}}}), "the camera gives a colour image");
  EXPECT_CONTAINS(ChainError({{"point_cloud", {}}}),
                  "'point_cloud' needs a depth image; the camera gives a colour image: put "
                  "'depth'");
  EXPECT_CONTAINS(ChainError({{"hsv_threshold", {}}, {"blobs", {}}, {"grayscale", {}}}),
                  "'grayscale' needs a colour image; 'blobs' gives values (no image): put "
                  "'original'");
  // 'original' takes anything: two colours in one chain, two blob packets.
  const FilterChain two = Chain({{"color_threshold", {{"color", {1, 0, 0}}}},
                                 {"blobs", {}},
                                 {"original", {}},
                                 {"color_threshold", {{"color", {0, 0, 1}}}},
                                 {"blobs", {}}});
  Image image = Filled(8, 8, 255, 0, 0);
  image.Pixel(7, 7)[0] = 0, image.Pixel(7, 7)[2] = 255;
  const FilterOutput out = two.Run(image, {});
  ASSERT_EQ(out.packets.size(), 3u);
  EXPECT_EQ(out.packets[1][2] * 64, 63);
  EXPECT_EQ(out.packets[2][2] * 64, 1);
}

TEST(VisionFiltersTest, UnknownElementsKeysAndBadValuesAreErrors) {
  EXPECT_CONTAINS(ChainError({{"blob", {}}}),
                  "filters[0].type: unknown 'blob'; did you mean 'blobs'?");
  EXPECT_CONTAINS(ChainError({{"blobs", {{"min_pixel", {3}}}}}),
                  "filters[0].min_pixel: unknown key 'min_pixel'; did you mean 'min_pixels'?");
  EXPECT_CONTAINS(ChainError({{"resize", {{"width", {0}}, {"height", {4}}}}}),
                  "filters[0].width: must be an integer from 1");
  EXPECT_CONTAINS(ChainError({{"resize", {{"width", {4}}}}}),
                  "'resize' needs 'width' and 'height'");
  EXPECT_CONTAINS(ChainError({{"hsv_threshold", {{"saturation", {0.8, 0.2}}}}}),
                  "'saturation' must be [min, max] with min <= max");
}

TEST(VisionFiltersTest, ExamplePluginsElementsRunInAChain) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadPlugin(
      (std::filesystem::path(SWARMSIM_BINARY).parent_path() / "plugins" / "example_plugin.so")
          .string(),
      &registry);
  ASSERT_NE(registry.FindVisionFilter("invert"), nullptr);
  Image image = Filled(8, 4, 200, 100, 0);
  image.Pixel(0, 0)[0] = 0;
  // brightness (its keys read from the item, its packet kept), then invert
  // on the mask: the background is the blob.
  const FilterChain chain =
      Chain({{"brightness", {{"gain", {0.5}}, {"offset", {0.1}}}},
             {"color_threshold", {{"color", {0.5, 0.3, 0.1}}, {"tolerance", {0.02}}}},
             {"invert", {}},
             {"blobs", {}}},
            &registry);
  const FilterOutput out = chain.Run(image, {});
  ASSERT_EQ(out.packets.size(), 3u);  // statistics, brightness, blobs
  ASSERT_EQ(out.packets[1].size(), 1u);
  // brightness: 0.5 v + 25.5 -> 125.5 -> 126, 75.5 -> 76, 25.5 -> 26 (and 26 for the 0 pixel).
  const double mean = ((126 + 76 + 26) * 32 - 126 + 26) / (255.0 * 96);
  EXPECT_NEAR(out.packets[1][0], mean, 1e-12);
  ASSERT_EQ(out.blobs.size(), 1u);
  EXPECT_EQ(out.blobs[0].pixels, 1);  // the inverted mask: only the odd pixel
  EXPECT_EQ(out.blobs[0].min_x, 0);
  // Its keys are checked like the built-ins'.
  try {
    Chain({{"brightness", {{"gain", {99}}}}}, &registry);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "filters[0].gain: must be a number from 0 to 16");
  }
  // Not without the plugin; a registry without elements has the built-in ones.
  EXPECT_CONTAINS(ChainError({{"invert", {}}}), "unknown 'invert'");
  const ModuleRegistry empty;
  EXPECT_EQ(Chain({{"grayscale", {}}}, &empty).size(), 1u);
}

TEST(VisionFiltersTest, OneChainRunsOnManyThreadsWithTheSameResults) {
  Image image = Filled(64, 48, 10, 10, 10);
  const uint8_t red[3] = {255, 0, 0};
  DrawEllipse(&image, 20, 20, 9, 3, 20 * kDeg, red);
  DrawEllipse(&image, 50, 30, 4, 4, 0, red);
  const FilterChain chain =
      Chain({{"hsv_threshold", {{"hue", {340, 20}}, {"saturation", {0.5, 1}}}}, {"blobs", {}}});
  const FilterChain copy = chain;  // shares the elements
  const FilterOutput expected = chain.Run(image, {});
  std::vector<FilterOutput> outs(4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int k = 0; k < 50; ++k) (t % 2 ? copy : chain).Run(image, {}, &outs[t]);
    });
  for (std::thread& t : threads) t.join();
  for (const FilterOutput& out : outs) {
    EXPECT_EQ(out.packets, expected.packets);
    EXPECT_EQ(out.image.rgb, expected.image.rgb);
  }
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
