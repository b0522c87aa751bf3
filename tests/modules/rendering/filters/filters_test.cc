// Vision-sensor filter chains (filters.cc) on synthetic images: the
// statistics packet, chain typing, unknown elements and bad values, the
// example plugin's elements in a chain, and a chain shared between threads.

#include "modules/rendering/filters/filters.h"

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

std::string ChainError(std::vector<FilterItem> items) {
  try {
    Chain(std::move(items));
  } catch (const Error& e) {
    return e.what();
  }
  return "NO ERROR";
}

using testing::DrawEllipse;
using testing::Drawn;
using testing::Filled;

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
