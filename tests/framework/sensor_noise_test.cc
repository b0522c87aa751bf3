// framework/sensor_noise.h: the streams devices draw their noise from, and
// that a device without noise draws nothing.
#include "framework/sensor_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace swarmsim {
namespace {

uint64_t First(uint64_t seed, uint32_t slot, int64_t step, NoisePurpose purpose) {
  Rng rng = NoiseStream(seed, slot, step, purpose);
  return rng.NextU64();
}

TEST(SensorNoiseTest, EachDeviceStepAndPurposeHasItsOwnStream) {
  std::set<uint64_t> seen;
  for (uint32_t slot : {0u, 1u, 2u, 1000u, (1u << 25) + 3})
    for (int64_t step : {0, 1, 2, 100000})
      for (NoisePurpose p :
           {NoisePurpose::kProximity, NoisePurpose::kWheels, NoisePurpose::kRangeAndBearing})
        seen.insert(First(1, slot, step, p));
  EXPECT_EQ(seen.size(), 5u * 4u * 3u);
  // The same key is the same stream; another seed another.
  EXPECT_EQ(First(1, 7, 9, NoisePurpose::kLight), First(1, 7, 9, NoisePurpose::kLight));
  EXPECT_NE(First(1, 7, 9, NoisePurpose::kLight), First(2, 7, 9, NoisePurpose::kLight));
  // Never a robot's own stream (World: Rng(seed, robot index)).
  for (uint64_t robot = 0; robot < 100; ++robot) EXPECT_EQ(seen.count(Rng(1, robot).NextU64()), 0u);
}

TEST(SensorNoiseTest, NoNoiseDrawsNothing) {
  const NoiseSettings none;
  EXPECT_FALSE(none.any());
  Rng rng(3, 4), untouched(3, 4);
  EXPECT_EQ(Perturb(none, 0.25, rng), 0.25);
  EXPECT_FALSE(Fails(none, rng));
  EXPECT_EQ(rng.NextU64(), untouched.NextU64());
}

TEST(SensorNoiseTest, PerturbAddsGaussianAndUniformNoise) {
  NoiseSettings n;
  n.gaussian = 0.5;
  n.uniform = 1.0;
  Rng rng(1, 2);
  double sum = 0, sq = 0;
  const int count = 20000;
  for (int i = 0; i < count; ++i) {
    const double e = Perturb(n, 3.0, rng) - 3.0;
    sum += e, sq += e * e;
  }
  // Variance 0.25 + 1/3.
  EXPECT_NEAR(sum / count, 0, 4 * std::sqrt(0.5833 / count));
  EXPECT_NEAR(sq / count, 0.25 + 1.0 / 3, 0.03);
  n = {};
  n.failure = 1;
  EXPECT_TRUE(Fails(n, rng));
}

}  // namespace
}  // namespace swarmsim
