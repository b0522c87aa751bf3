// Summary statistics of sweep reports (swarm/sweep/stats.cc): Student's t
// critical values, mean, sample standard deviation and the 95% interval.
#include "swarm/sweep/stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace swarmsim {
namespace {

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
