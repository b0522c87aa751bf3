// Range-and-bearing boards as a user checks them: range and bearing against
// geometry computed by hand, occluders placed by hand, loss rates and noise
// histograms against the configured probabilities and distributions,
// capacity, and the same readings whatever the thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "framework/random.h"
#include "tests/modules/range_and_bearing/rab_world.h"

namespace swarmsim::range_and_bearing {
namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kDeg = kPi / 180;

RangeAndBearingSettings Board(double range = 3) {
  RangeAndBearingSettings s;
  s.range = range;
  return s;
}

TEST(RangeAndBearingTest, RangeAndBearingAreInTheReceiversFrame) {
  RabWorld w;
  // The receiver faces +y (yaw 90 deg); the sender is at (1, 1), its board
  // 0.1 m higher.
  const ObjectId receiver = w.Robot(0, 0, 90 * kDeg, Board());
  const ObjectId sender = w.Robot(1, 1, 0, Board(), 0.1);
  const auto heard = w.Step(receiver);
  ASSERT_EQ(heard.size(), 1u);
  // In the receiver's frame the sender is at (1, -1, 0.1): ahead and to the right.
  EXPECT_NEAR(heard[0].range, std::sqrt(2.01), 1e-12);
  EXPECT_NEAR(heard[0].bearing, -kPi / 4, 1e-12);
  EXPECT_NEAR(heard[0].elevation, std::atan2(0.1, std::sqrt(2.0)), 1e-12);
  EXPECT_EQ(heard[0].sender, sender);
  // And the sender hears the receiver behind it to the left (135 deg), below.
  const auto back = w.Readings(sender);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_NEAR(back[0].bearing, -3 * kPi / 4, 1e-12);
  EXPECT_NEAR(back[0].elevation, -std::atan2(0.1, std::sqrt(2.0)), 1e-12);
}

TEST(RangeAndBearingTest, StraightBehindIsPlusPiAndAPayloadIsPaddedToItsSize) {
  RabWorld w;
  const ObjectId receiver = w.Robot(0, 0, 0, Board());
  const ObjectId sender = w.Robot(-2, 0, 0, Board());
  w.SetData(sender, "hi");
  const auto heard = w.Step(receiver);
  ASSERT_EQ(heard.size(), 1u);
  EXPECT_DOUBLE_EQ(heard[0].bearing, kPi);
  EXPECT_DOUBLE_EQ(heard[0].range, 2);
  EXPECT_EQ(heard[0].data, std::string("hi\0\0\0\0\0\0\0\0", 10));  // foot-bot: 10 bytes
  // A board that never set anything sends zeros.
  ASSERT_EQ(w.Readings(sender).size(), 1u);
  EXPECT_EQ(w.Readings(sender)[0].data, std::string(10, '\0'));
}

TEST(RangeAndBearingTest, OnlyOtherRobotsWithinRangeAreHeard) {
  RabWorld w;
  const ObjectId receiver = w.Robot(0, 0, 0, Board(0.8));  // an e-puck's range
  w.Robot(0.79, 0, 0, Board());
  w.Robot(0, 0.81, 0, Board());
  // A second board on the receiver's own robot is not heard either.
  const ObjectId second = w.SecondBoard(receiver, Board(), 0.05);
  const auto heard = w.Step(receiver);
  ASSERT_EQ(heard.size(), 1u);
  EXPECT_NEAR(heard[0].range, 0.79, 1e-12);
  // The second board hears the two others (its range is 3 m), not its own robot's.
  EXPECT_EQ(w.Readings(second).size(), 2u);
}

TEST(RangeAndBearingTest, AStaticWallBlocksUnlessOcclusionIsOff) {
  for (const bool occlusion : {true, false}) {
    SCOPED_TRACE(occlusion);
    RabWorld w;
    RangeAndBearingSettings s = Board();
    s.occlusion = occlusion;
    const ObjectId a = w.Robot(0, 0, 0, s);
    const ObjectId b = w.Robot(2, 0, 0, s);
    const ObjectId c = w.Robot(0, 2, 0, s);
    // A wall across the line from a to b, not between a and c.
    w.Wall({1, 0, 0.25}, {0.05, 1, 0.5});
    const auto heard = w.Step(a);
    std::vector<ObjectId> senders;
    for (const Heard& h : heard) senders.push_back(h.sender);
    if (occlusion)
      EXPECT_EQ(senders, std::vector<ObjectId>{c});
    else
      EXPECT_EQ(senders.size(), 2u);
    // Both ways: b hears c (2.83 m, past the wall's end) and a only without occlusion.
    std::vector<ObjectId> b_hears;
    for (const Heard& h : w.Readings(b)) b_hears.push_back(h.sender);
    if (occlusion)
      EXPECT_EQ(b_hears, std::vector<ObjectId>{c});
    else
      EXPECT_EQ(b_hears, (std::vector<ObjectId>{a, c}));
  }
}

TEST(RangeAndBearingTest, AWallBelowTheBoardsDoesNotBlock) {
  RabWorld w;
  const ObjectId a = w.Robot(0, 0, 0, Board());
  w.Robot(2, 0, 0, Board());
  w.Wall({1, 0, 0.05}, {0.05, 1, 0.1});  // 0.1 m high; boards 0.123 m up
  EXPECT_EQ(w.Step(a).size(), 1u);
}

TEST(RangeAndBearingTest, ARobotBodyBlocksOnlyWithRobotOcclusion) {
  for (const bool robot_occlusion : {false, true}) {
    SCOPED_TRACE(robot_occlusion);
    RabWorld w;
    RangeAndBearingSettings s = Board();
    s.robot_occlusion = robot_occlusion;
    const ObjectId a = w.Robot(0, 0, 0, s);
    const ObjectId middle = w.Robot(1, 0, 0, s);
    const ObjectId far = w.Robot(2, 0, 0, s);
    const auto heard = w.Step(a);
    std::vector<ObjectId> senders;
    for (const Heard& h : heard) senders.push_back(h.sender);
    if (robot_occlusion)
      EXPECT_EQ(senders, std::vector<ObjectId>{middle});
    else
      EXPECT_EQ(senders, (std::vector<ObjectId>{middle, far}));
    // The two robots' own bodies, which the boards sit in, never block.
    EXPECT_EQ(w.Readings(middle).size(), 2u);
    (void)far;
  }
}

// Over many steps, the share of messages heard is the configured one
// within binomial bounds (5 sigma).
TEST(RangeAndBearingTest, LossRatesMatchTheirProbabilities) {
  struct Case {
    double loss, at_range, distance, expected_loss;
  };
  // p = min(1, loss_probability + loss_at_range (d / range)^2), range 2.
  for (const Case c : {Case{0.3, 0, 1, 0.3}, Case{0, 0.8, 1, 0.2}, Case{0.1, 0.5, 2, 0.6},
                       Case{0.6, 0.9, 2, 1.0}}) {
    SCOPED_TRACE(c.expected_loss);
    RabWorld w;
    RangeAndBearingSettings s = Board(2);
    s.loss_probability = c.loss;
    s.loss_at_range = c.at_range;
    const ObjectId receiver = w.Robot(0, 0, 0, s);
    w.Robot(c.distance, 0, 0, s);
    constexpr int kSteps = 3000;
    int heard = 0;
    for (int i = 0; i < kSteps; ++i) heard += static_cast<int>(w.Step(receiver).size());
    const double p = 1 - c.expected_loss;
    const double sigma = std::sqrt(kSteps * p * (1 - p));
    EXPECT_NEAR(heard, kSteps * p, 5 * sigma + 0.5);
  }
}

TEST(RangeAndBearingTest, AFailingBoardHearsNothingAtThatRate) {
  RabWorld w;
  RangeAndBearingSettings s = Board();
  s.range_noise.failure = 0.25;
  const ObjectId receiver = w.Robot(0, 0, 0, s);
  for (int i = 0; i < 4; ++i) w.Robot(0.5 + 0.3 * i, 0.2, 0, Board());
  constexpr int kSteps = 2000;
  int silent = 0;
  for (int i = 0; i < kSteps; ++i) {
    const size_t n = w.Step(receiver).size();
    EXPECT_TRUE(n == 0 || n == 4) << n;  // all or nothing
    silent += n == 0;
  }
  EXPECT_NEAR(silent, 0.25 * kSteps, 5 * std::sqrt(kSteps * 0.25 * 0.75));
}

struct Moments {
  double mean = 0, stddev = 0, min = 1e300, max = -1e300;
};
Moments Of(const std::vector<double>& v) {
  Moments m;
  m.mean = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
  double ss = 0;
  for (double x : v) {
    ss += (x - m.mean) * (x - m.mean);
    m.min = std::min(m.min, x);
    m.max = std::max(m.max, x);
  }
  m.stddev = std::sqrt(ss / (v.size() - 1));
  return m;
}

// Noise histograms: the mean and std dev of many readings are the true
// value and the configured std dev, within statistical bounds; uniform
// noise stays within its half width and fills it.
TEST(RangeAndBearingTest, NoiseHasTheConfiguredDistribution) {
  RabWorld w;
  RangeAndBearingSettings s = Board();
  s.range_noise.gaussian = 0.05;
  s.bearing_noise.gaussian = 5 * kDeg;
  const ObjectId receiver = w.Robot(0, 0, 0, s);
  RangeAndBearingSettings u = Board();
  u.range_noise.uniform = 0.1;
  u.bearing_noise.uniform = 10 * kDeg;
  const ObjectId uniform = w.Robot(1.2, 1.6, 0, u);  // 2 m from the receiver, at 53.13 deg
  const double bearing = std::atan2(1.6, 1.2);
  constexpr int kSteps = 4000;
  std::vector<double> ranges, bearings, elevations, u_ranges, u_bearings;
  for (int i = 0; i < kSteps; ++i) {
    const auto heard = w.Step(receiver);
    ASSERT_EQ(heard.size(), 1u);
    ranges.push_back(heard[0].range);
    bearings.push_back(heard[0].bearing);
    elevations.push_back(heard[0].elevation);
    const auto back = w.Readings(uniform);
    ASSERT_EQ(back.size(), 1u);
    u_ranges.push_back(back[0].range);
    u_bearings.push_back(back[0].bearing);
  }
  const double n = kSteps;
  const auto expect_gaussian = [n](const Moments& m, double mean, double sigma) {
    EXPECT_NEAR(m.mean, mean, 5 * sigma / std::sqrt(n));
    EXPECT_NEAR(m.stddev, sigma, 5 * sigma / std::sqrt(2 * n));
  };
  expect_gaussian(Of(ranges), 2, 0.05);
  expect_gaussian(Of(bearings), bearing, 5 * kDeg);
  expect_gaussian(Of(elevations), 0, 5 * kDeg);
  // Uniform on [-a, a]: std dev a / sqrt(3).
  const Moments ur = Of(u_ranges), ub = Of(u_bearings);
  const double back_bearing = bearing - kPi;
  EXPECT_GE(ur.min, 2 - 0.1);
  EXPECT_LE(ur.max, 2 + 0.1);
  EXPECT_LT(ur.min, 2 - 0.09);
  EXPECT_GT(ur.max, 2 + 0.09);
  EXPECT_NEAR(ur.mean, 2, 5 * 0.1 / std::sqrt(3 * n));
  EXPECT_NEAR(ur.stddev, 0.1 / std::sqrt(3.0), 0.005);
  EXPECT_GE(ub.min, back_bearing - 10 * kDeg - 1e-12);
  EXPECT_LE(ub.max, back_bearing + 10 * kDeg + 1e-12);
  EXPECT_NEAR(ub.mean, back_bearing, 5 * 10 * kDeg / std::sqrt(3 * n));
  EXPECT_NEAR(ub.stddev, 10 * kDeg / std::sqrt(3.0), 0.05 * 10 * kDeg);
}

TEST(RangeAndBearingTest, ABoardWithoutNoiseReadsExactlyTheSameEveryStep) {
  RabWorld w;
  const ObjectId receiver = w.Robot(0, 0, 0.3, Board());
  w.Robot(1, 0.5, 0, Board());
  const auto first = w.Step(receiver);
  for (int i = 0; i < 5; ++i) {
    const auto again = w.Step(receiver);
    ASSERT_EQ(again.size(), 1u);
    EXPECT_EQ(again[0].range, first[0].range);
    EXPECT_EQ(again[0].bearing, first[0].bearing);
  }
}

// Five senders 0.5 .. 2.5 m away in different directions, each sending its
// number.
struct CapacityWorld {
  explicit CapacityWorld(const RangeAndBearingSettings& s) {
    receiver = w.Robot(0, 0, 0, s);
    const double distances[] = {1.5, 0.5, 2.5, 1.0, 2.0};  // sender i sends i + 1
    for (int i = 0; i < 5; ++i) {
      const double a = 1.3 * i;
      const ObjectId b =
          w.Robot(distances[i] * std::cos(a), distances[i] * std::sin(a), 0, Board());
      w.SetData(b, std::string(1, static_cast<char>(i + 1)));
    }
  }
  RabWorld w;
  ObjectId receiver;
};

TEST(RangeAndBearingTest, CapacityNearestKeepsTheNearestInOrder) {
  RangeAndBearingSettings s = Board();
  s.capacity = 2;
  CapacityWorld c(s);
  const auto heard = c.w.Step(c.receiver);
  ASSERT_EQ(heard.size(), 2u);
  EXPECT_EQ(heard[0].data[0], 2);  // 0.5 m
  EXPECT_EQ(heard[1].data[0], 4);  // 1.0 m
  EXPECT_NEAR(heard[0].range, 0.5, 1e-12);
  // Without a capacity: all five, nearest first.
  CapacityWorld all(Board());
  const auto five = all.w.Step(all.receiver);
  ASSERT_EQ(five.size(), 5u);
  std::string order;
  for (const Heard& h : five) order += static_cast<char>('0' + h.data[0]);
  EXPECT_EQ(order, "24153");
}

TEST(RangeAndBearingTest, CapacityNearestCountsOnlyWhatIsHeard) {
  // The two nearest are lost behind a wall: the next two are kept.
  RangeAndBearingSettings s = Board();
  s.capacity = 2;
  RabWorld w;
  const ObjectId receiver = w.Robot(0, 0, 0, s);
  w.Robot(0.5, 0, 0, Board());
  w.Robot(0.8, 0, 0, Board());
  const ObjectId c = w.Robot(0, 1, 0, Board());
  const ObjectId d = w.Robot(0, -1.5, 0, Board());
  w.Robot(-2, 0, 0, Board());
  w.Wall({0.3, 0, 0.25}, {0.02, 0.5, 0.5});
  const auto heard = w.Step(receiver);
  ASSERT_EQ(heard.size(), 2u);
  EXPECT_EQ(heard[0].sender, c);
  EXPECT_EQ(heard[1].sender, d);
}

TEST(RangeAndBearingTest, CapacityRandomPicksEachSenderEquallyOften) {
  RangeAndBearingSettings s = Board();
  s.capacity = 2;
  s.capacity_order = CapacityOrder::kRandom;
  CapacityWorld c(s);
  constexpr int kSteps = 2000;
  std::map<int, int> picked;
  for (int i = 0; i < kSteps; ++i) {
    const auto heard = c.w.Step(c.receiver);
    ASSERT_EQ(heard.size(), 2u);
    EXPECT_LE(heard[0].range, heard[1].range);  // still nearest first
    EXPECT_NE(heard[0].data, heard[1].data);
    for (const Heard& h : heard) ++picked[h.data[0]];
  }
  ASSERT_EQ(picked.size(), 5u);
  const double p = 2.0 / 5;
  for (const auto& [sender, count] : picked)
    EXPECT_NEAR(count, kSteps * p, 5 * std::sqrt(kSteps * p * (1 - p))) << sender;
}

TEST(RangeAndBearingTest, DataIsKeptUntilChanged) {
  RabWorld w;
  const ObjectId receiver = w.Robot(0, 0, 0, Board());
  const ObjectId sender = w.Robot(1, 0, 0, Board());
  w.SetData(sender, "abc");
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(w.Step(receiver)[0].data.substr(0, 4), std::string("abc\0", 4));
  w.SetData(sender, "z");
  EXPECT_EQ(w.Step(receiver)[0].data.substr(0, 2), std::string("z\0", 2));
}

// A swarm with every option on: the readings and the state hash are the
// same at 1, 2 and 4 threads.
TEST(RangeAndBearingTest, ReadingsAreTheSameForAnyThreadCount) {
  const auto run = [](int threads, std::vector<std::vector<Heard>>* out) {
    RabWorld w(threads, 7);
    RangeAndBearingSettings s = Board(1.5);
    s.loss_probability = 0.1;
    s.loss_at_range = 0.3;
    s.range_noise.gaussian = 0.02;
    s.bearing_noise.gaussian = 0.05;
    s.range_noise.failure = 0.05;
    s.capacity = 6;
    s.capacity_order = CapacityOrder::kRandom;
    s.robot_occlusion = true;
    Rng place(3, 0);
    std::vector<ObjectId> boards;
    for (int i = 0; i < 400; ++i) {
      const ObjectId b =
          w.Robot(place.Uniform(-5, 5), place.Uniform(-5, 5), place.Uniform(-kPi, kPi), s);
      w.SetData(b, std::string(1, static_cast<char>(i % 251)));
      boards.push_back(b);
    }
    w.Wall({0, 0, 0.25}, {0.1, 6, 0.5});
    for (int step = 0; step < 3; ++step) w.Step(boards[0]);
    out->clear();
    for (ObjectId b : boards) out->push_back(w.Readings(b));
    return w.world().StateHash();
  };
  std::vector<std::vector<Heard>> one, two, four;
  const uint64_t h1 = run(1, &one), h2 = run(2, &two), h4 = run(4, &four);
  EXPECT_EQ(h1, h2);
  EXPECT_EQ(h1, h4);
  size_t total = 0;
  for (size_t i = 0; i < one.size(); ++i) {
    ASSERT_EQ(one[i].size(), two[i].size()) << i;
    ASSERT_EQ(one[i].size(), four[i].size()) << i;
    total += one[i].size();
    for (size_t k = 0; k < one[i].size(); ++k) {
      EXPECT_EQ(one[i][k].range, two[i][k].range);
      EXPECT_EQ(one[i][k].bearing, four[i][k].bearing);
      EXPECT_EQ(one[i][k].data, two[i][k].data);
    }
  }
  EXPECT_GT(total, 400u);  // something was heard
}

TEST(RangeAndBearingTest, TheStateHashSeesWhatIsSentAndHeard) {
  RabWorld w;
  const ObjectId a = w.Robot(0, 0, 0, Board());
  w.Robot(1, 0, 0, Board());
  w.Step(a);
  const uint64_t before = w.world().StateHash();
  w.SetData(a, "x");
  EXPECT_NE(w.world().StateHash(), before);
}

}  // namespace
}  // namespace swarmsim::range_and_bearing
