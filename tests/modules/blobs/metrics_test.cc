// The colour-clustering swarm metrics of modules/blobs (metrics.cc):
// same_color_neighbor_fraction and color_dispersion tell segregated robots
// from mixed ones.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"
#include "tests/modules/blobs/blob_world.h"

namespace swarmsim {
namespace {

using namespace blobs_test;  // blob_world.h

// --- Metrics -----------------------------------------------------------------------------

// The two colour metrics of robots with LEDs at (x, 0), colours[i].
std::pair<double, double> ColorMetrics(const std::vector<double>& xs,
                                       const std::vector<Vec3>& colors) {
  BlobWorld w;
  for (size_t i = 0; i < xs.size(); ++i) w.LedRobot(xs[i], 0, colors[i]);
  w.Robot(0.05, 0.05);  // no LED: does not count
  const int every = 1;
  w.world().AddModule("same_color_neighbor_fraction", &every);
  w.world().AddModule("color_dispersion", &every);
  w.world().Step();
  std::pair<double, double> out{-1, -1};
  for (const MetricSample& m : w.world().TakeMetrics()) {
    if (m.name == "same_color_neighbor_fraction") out.first = m.value;
    if (m.name == "color_dispersion") out.second = m.value;
  }
  return out;
}

TEST(BlobCameraTest, ColourMetricsTellSegregatedFromMixed) {
  // Two far groups of four, one colour each: every neighbour is one's own
  // colour; each robot is 0.15 or 0.05 m from its group's centre.
  const auto [together, spread] =
      ColorMetrics({0, 0.1, 0.2, 0.3, 10, 10.1, 10.2, 10.3},
                   {kRed, kRed, kRed, kRed, kBlue, kBlue, kBlue, kBlue});
  EXPECT_DOUBLE_EQ(together, 1.0);
  EXPECT_NEAR(spread, 0.1, 1e-12);
  // Alternating on a line 1 m apart: of the 3 nearest, one shares the colour.
  std::vector<double> xs;
  std::vector<Vec3> colors;
  for (int i = 0; i < 8; ++i) {
    xs.push_back(i);
    colors.push_back(i % 2 == 0 ? kRed : kBlue);
  }
  const auto [mixed, mixed_spread] = ColorMetrics(xs, colors);
  EXPECT_NEAR(mixed, 1.0 / 3, 1e-12);
  EXPECT_NEAR(mixed_spread, 2.0, 1e-12);  // |i - 3| or |i - 4| over each colour: 3, 1, 1, 3
}

}  // namespace
}  // namespace swarmsim
