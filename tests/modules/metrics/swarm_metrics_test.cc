// The built-in swarm metrics (modules/metrics/swarm_metrics.cc) through a
// World: mean_nearest_neighbor_distance and covered_area against hand
// computations, `every`, removed robots, and a bad `every` refused.
#include "modules/metrics/swarm_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/modules/module_world.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;
using testing::ModuleWorld;

// The samples of metric `name` so far.
std::vector<MetricSample> Samples(World& world, const std::string& name) {
  std::vector<MetricSample> out;
  for (MetricSample& m : world.TakeMetrics())
    if (m.name == name) out.push_back(std::move(m));
  return out;
}

// Robots at (0, 0), (3, 0) and (3, 4): nearest neighbours 3, 3 and 4 m away.
TEST(SwarmMetricsTest, MeanNearestNeighbourDistanceIsTheMeanOfEachRobotsNearest) {
  ModuleWorld w;
  w.Robot("a", {{0, 0, 0}, {}});
  w.Robot("b", {{3, 0, 0}, {}});
  w.Robot("c", {{3, 4, 0.5}, {}});  // height does not count
  w.world().AddModule("mean_nearest_neighbor_distance", nullptr);
  ASSERT_EQ(w.Run(2), "");
  const std::vector<MetricSample> samples = Samples(w.world(), "mean_nearest_neighbor_distance");
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].step, 1);
  EXPECT_EQ(samples[1].step, 2);
  EXPECT_EQ(samples[0].instance, -1);
  EXPECT_NEAR(samples[1].value, (3.0 + 3.0 + 4.0) / 3, 1e-12);
}

// Far apart (the grid's search grows until it finds someone) and a removed
// robot left out.
TEST(SwarmMetricsTest, FarNeighboursAreFoundAndRemovedRobotsLeftOut) {
  ModuleWorld w;
  w.Robot("a", {{0, 0, 0}, {}});
  w.Robot("b", {{0.1, 0, 0}, {}});
  const ObjectId far = w.Robot("c", {{500, 0, 0}, {}});
  w.world().AddModule("mean_nearest_neighbor_distance", nullptr);
  ASSERT_EQ(w.Run(1), "");
  auto samples = Samples(w.world(), "mean_nearest_neighbor_distance");
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_NEAR(samples[0].value, (0.1 + 0.1 + 499.9) / 3, 1e-9);
  w.scene().RemoveSubtree(far);
  ASSERT_EQ(w.Run(1), "");
  samples = Samples(w.world(), "mean_nearest_neighbor_distance");
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_NEAR(samples[0].value, 0.1, 1e-12);
}

TEST(SwarmMetricsTest, ALoneRobotHasNoNearestNeighbour) {
  ModuleWorld w;
  w.Robot("a", {});
  w.world().AddModule("mean_nearest_neighbor_distance", nullptr);
  ASSERT_EQ(w.Run(3), "");
  EXPECT_TRUE(Samples(w.world(), "mean_nearest_neighbor_distance").empty());
}

// Cells of 0.25 m visited since the start, the starting ones included: a
// robot moved through three cells, another resting in one; recorded every second step, counting the
// cells visited in between.
TEST(SwarmMetricsTest, CoveredAreaCountsTheCellsVisitedSinceTheStart) {
  ModuleWorld w;
  const ObjectId mover = w.Robot("mover", {{0.1, 0.1, 0}, {}});
  w.Robot("rest", {{-0.1, -0.1, 0}, {}});
  const int every = 2;
  w.world().AddModule("covered_area", &every);
  ASSERT_EQ(w.Run(0), "");
  for (const double x : {0.3, 0.6, 0.6, 0.6}) {
    w.scene().SetLocalPose(mover, {{x, 0.1, 0}, {}});
    ASSERT_EQ(w.Run(1), "");
  }
  const std::vector<MetricSample> samples = Samples(w.world(), "covered_area");
  ASSERT_EQ(samples.size(), 2u);  // steps 2 and 4
  EXPECT_EQ(samples[0].step, 2);
  // The start saw cells (0, 0) and (-1, -1) (it was left out: the first
  // record is after step 1), step 1 (1, 0), step 2 (2, 0).
  EXPECT_DOUBLE_EQ(samples[0].value, 4 * 0.0625);
  EXPECT_DOUBLE_EQ(samples[1].value, 4 * 0.0625);
}

TEST(SwarmMetricsTest, EveryBelowOneIsRefused) {
  ModuleWorld w;
  const int zero = 0;
  EXPECT_CONTAINS(ErrorOf([&] { w.world().AddModule("covered_area", &zero); }),
                  "a metric's 'every' must be >= 1");
  const std::vector<ModuleDescriptor> modules = metrics::SwarmMetricModules();
  ASSERT_EQ(modules.size(), 2u);
  EXPECT_EQ(modules[0].info.kind, "metric");
}

}  // namespace
}  // namespace swarmsim
