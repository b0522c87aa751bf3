#include "framework/random.h"

#include <gtest/gtest.h>

#include <cmath>

namespace swarmsim {
namespace {

TEST(RngTest, StreamsAreReproducibleAndDistinct) {
  Rng a(42, 7), b(42, 7), c(42, 8), d(43, 7);
  for (int i = 0; i < 100; ++i) {
    const uint64_t va = a.NextU64();
    EXPECT_EQ(va, b.NextU64());
    EXPECT_NE(va, c.NextU64());
    EXPECT_NE(va, d.NextU64());
  }
}

TEST(RngTest, UniformHasTheRightMoments) {
  Rng rng(1, 0);
  double sum = 0, sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double u = rng.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  EXPECT_NEAR(sum / n, 0.5, 0.005);
  EXPECT_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12, 0.002);
  int counts[6] = {};
  for (int i = 0; i < 60000; ++i) ++counts[rng.UniformInt(0, 5)];
  for (int c : counts) EXPECT_NEAR(c, 10000, 500);
  double nsum = 0, nsum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = rng.Normal(2, 3);
    nsum += x;
    nsum2 += x * x;
  }
  EXPECT_NEAR(nsum / n, 2, 0.05);
  EXPECT_NEAR(std::sqrt(nsum2 / n - (nsum / n) * (nsum / n)), 3, 0.05);
}

}  // namespace
}  // namespace swarmsim
