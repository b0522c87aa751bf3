// Blob detection (filters/blobs.cc) on synthetic images: blobs of drawn
// discs and ellipses with their size, centroid, box, colour and
// orientation; min_pixels.

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

using testing::DrawEllipse;
using testing::Drawn;
using testing::Filled;

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

}  // namespace
}  // namespace swarmsim::filters
