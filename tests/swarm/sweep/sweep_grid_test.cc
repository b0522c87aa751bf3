// Sweep grids (parameter specs, seeds, cartesian product) and the report's
// statistics (Student t, mean, sd, 95% CI) against known values.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "framework/error.h"
#include "swarm/sweep/grid.h"
#include "swarm/sweep/stats.h"

namespace swarmsim {
namespace {

using Values = std::vector<std::string>;

TEST(SweepGridTest, ListsAndLinearAndLogRanges) {
  EXPECT_EQ(ParseParamSpec("robots=100,200,400").values, (Values{"100", "200", "400"}));
  EXPECT_EQ(ParseParamSpec("robots=100,200,400").kind, "list");
  EXPECT_EQ(ParseParamSpec("mode=fast").values, (Values{"fast"}));
  const ParamSpec lin = ParseParamSpec("density=0.05:0.20:4");
  EXPECT_EQ(lin.name, "density");
  EXPECT_EQ(lin.kind, "linear");
  EXPECT_EQ(lin.values, (Values{"0.05", "0.1", "0.15", "0.2"}));
  EXPECT_EQ(ParseParamSpec("n=1:5:5").values, (Values{"1", "2", "3", "4", "5"}));
  const ParamSpec log = ParseParamSpec("rate=log:0.01:10:4");
  EXPECT_EQ(log.kind, "log");
  EXPECT_EQ(log.values, (Values{"0.01", "0.1", "1", "10"}));
  EXPECT_EQ(ParseParamSpec("a=log:1:1000:7").values.back(), "1000");
  EXPECT_EQ(ParseParamSpec("footbot.wheel_speed=0.1:0.1:1").values, (Values{"0.1"}));
}

TEST(SweepGridTest, MalformedSpecsAreClearErrors) {
  for (const char* bad : {"robots", "=1,2", "robots=", "d=0.1:0.2", "d=0.1:x:3", "d=0.1:0.2:0",
                          "d=0.1:0.2:2.5", "d=log:0:1:3", "d=1,,2", "d=1,1", "d=0.1:0.2:1"}) {
    try {
      ParseParamSpec(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--param"), std::string::npos) << e.what();
    }
  }
}

TEST(SweepGridTest, Seeds) {
  EXPECT_EQ(ParseSeeds("3"), (std::vector<uint64_t>{1, 2, 3}));
  EXPECT_EQ(ParseSeeds("5-8"), (std::vector<uint64_t>{5, 6, 7, 8}));
  EXPECT_EQ(ParseSeeds("1-20").size(), 20u);
  EXPECT_EQ(ParseSeeds("11,3,7"), (std::vector<uint64_t>{11, 3, 7}));
  for (const char* bad : {"0", "x", "8-5", "1,1", "-3", "1.5"})
    EXPECT_THROW(ParseSeeds(bad), Error) << bad;
}

TEST(SweepGridTest, CartesianProductTimesSeedsLastParameterFastest) {
  const std::vector<ParamSpec> params{ParseParamSpec("a=1,2"), ParseParamSpec("b=x,y,z")};
  const std::vector<GridRun> runs = ExpandGrid(params, {7, 9});
  ASSERT_EQ(runs.size(), 2u * 3u * 2u);
  for (size_t i = 0; i < runs.size(); ++i) {
    EXPECT_EQ(runs[i].id, static_cast<int64_t>(i) + 1);  // as `report` and the database show them
    EXPECT_EQ(runs[i].point, static_cast<int64_t>(i / 2));
    EXPECT_EQ(runs[i].seed, i % 2 == 0 ? 7u : 9u);
  }
  using P = std::vector<std::pair<std::string, std::string>>;
  EXPECT_EQ(runs[0].params, (P{{"a", "1"}, {"b", "x"}}));
  EXPECT_EQ(runs[2].params, (P{{"a", "1"}, {"b", "y"}}));
  EXPECT_EQ(runs[6].params, (P{{"a", "2"}, {"b", "x"}}));
  EXPECT_EQ(runs[11].params, (P{{"a", "2"}, {"b", "z"}}));
  // Every combination exactly once.
  std::set<P> distinct;
  for (const GridRun& r : runs) distinct.insert(r.params);
  EXPECT_EQ(distinct.size(), 6u);
  // No parameters: one point per seed.
  EXPECT_EQ(ExpandGrid({}, {1, 2, 3}).size(), 3u);
  EXPECT_THROW(ExpandGrid({ParseParamSpec("a=1"), ParseParamSpec("a=2")}, {1}), Error);
}

TEST(StatsTest, StudentTAgainstKnownValues) {
  // Tabulated and interpolated entries against t(0.975, df) from mpmath.
  EXPECT_NEAR(StudentT975(1), 12.7062047, 1e-6);
  EXPECT_NEAR(StudentT975(2), 4.3026527, 1e-6);
  EXPECT_NEAR(StudentT975(4), 2.7764451, 1e-6);
  EXPECT_NEAR(StudentT975(10), 2.2281389, 1e-6);
  EXPECT_NEAR(StudentT975(19), 2.0930241, 1e-6);
  EXPECT_NEAR(StudentT975(30), 2.0422725, 1e-6);
  EXPECT_NEAR(StudentT975(33), 2.0345153, 2e-4);  // interpolated
  EXPECT_NEAR(StudentT975(75), 1.9921022, 2e-4);
  EXPECT_NEAR(StudentT975(250), 1.9694984, 2e-4);
  EXPECT_NEAR(StudentT975(2000), 1.9611508, 2e-4);
  EXPECT_NEAR(StudentT975(100000), 1.9599877, 2e-4);
  for (int64_t df = 1; df < 3000; ++df) EXPECT_GT(StudentT975(df), StudentT975(df + 1)) << df;
}

TEST(StatsTest, MeanSdAndConfidenceInterval) {
  const Summary s = Summarize({1, 2, 3, 4, 5});
  EXPECT_EQ(s.n, 5);
  EXPECT_DOUBLE_EQ(s.mean, 3.0);
  EXPECT_NEAR(s.sd, 1.5811388301, 1e-9);  // sample sd, n - 1
  // 3 -/+ t(0.975, 4) * sd / sqrt(5) = 3 -/+ 1.9632432
  EXPECT_NEAR(s.ci_low, 1.0367568, 1e-6);
  EXPECT_NEAR(s.ci_high, 4.9632432, 1e-6);
  const Summary two = Summarize({10, 12});
  EXPECT_NEAR(two.ci_high - two.mean, 12.7062047 * std::sqrt(2.0) / std::sqrt(2.0), 1e-6);
  const Summary one = Summarize({4});
  EXPECT_EQ(one.mean, 4);
  EXPECT_TRUE(std::isnan(one.sd));
  EXPECT_TRUE(std::isnan(one.ci_low));
  EXPECT_TRUE(std::isnan(Summarize({}).mean));
}

}  // namespace
}  // namespace swarmsim
