// IR messaging (modules/ir_messaging/module.cc): range, the distance
// estimate, carrier sense, hidden-terminal collisions, loss, and the same
// results for any thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "framework/random.h"
#include "tests/modules/ir_messaging/ir_world.h"

namespace swarmsim::ir_messaging {
namespace {

TEST(IrMessagingTest, HeardWithinRangeOnlyWithTheTrueDistance) {
  IrWorld w;
  const IrSettings s = Exact();  // range 0.1
  const ObjectId receiver = w.Robot(0, 0, s);
  const ObjectId near = w.Robot(0.099, 0, s);  // inside the range
  const ObjectId far = w.Robot(-0.101, 0, s);  // just outside
  w.Send(near, "near");
  w.Send(far, "far");
  w.Step();
  EXPECT_TRUE(w.Sent(near));
  EXPECT_TRUE(w.Sent(far));  // no one hears it, but it went out
  const std::vector<HeardMessage> heard = w.Heard(receiver);
  ASSERT_EQ(heard.size(), 1u);
  EXPECT_EQ(heard[0].data, "near");
  EXPECT_NEAR(heard[0].distance, 0.099, 1e-12);
  EXPECT_EQ(heard[0].sender, near);
  // Nothing queued: nothing goes out at the next step, nothing is heard.
  w.Step();
  EXPECT_FALSE(w.Sent(near));
  EXPECT_TRUE(w.Heard(receiver).empty());
}

TEST(IrMessagingTest, ARobotNeverHearsItself) {
  IrWorld w;
  const ObjectId a = w.Robot(0, 0, Exact());
  w.Send(a, "me");
  w.Step();
  EXPECT_TRUE(w.Sent(a));
  EXPECT_TRUE(w.Heard(a).empty());
}

TEST(IrMessagingTest, DistanceEstimateHasTheSettingsMeanAndSpread) {
  IrWorld w;
  IrSettings s;
  s.distance_noise = 0.004;
  const double d = 0.05;
  const ObjectId receiver = w.Robot(0, 0, s);
  const ObjectId sender = w.Robot(d, 0, s);
  const int n = 4000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    w.Send(sender, "x");
    w.Step();
    const std::vector<HeardMessage> heard = w.Heard(receiver);
    ASSERT_EQ(heard.size(), 1u);
    sum += heard[0].distance;
    sum2 += heard[0].distance * heard[0].distance;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  // The mean within 4 standard errors, the spread within 10 %.
  EXPECT_NEAR(mean, d, 4 * s.distance_noise / std::sqrt(n));
  EXPECT_NEAR(sd, s.distance_noise, 0.1 * s.distance_noise);
}

TEST(IrMessagingTest, DistanceEstimateIsNeverNegative) {
  IrWorld w;
  IrSettings s;
  s.distance_noise = 0.05;  // much more than the distance
  const ObjectId receiver = w.Robot(0, 0, s);
  const ObjectId sender = w.Robot(0.001, 0, s);
  bool clamped = false;
  for (int i = 0; i < 200; ++i) {
    w.Send(sender, "x");
    w.Step();
    ASSERT_EQ(w.Heard(receiver).size(), 1u);
    EXPECT_GE(w.Heard(receiver)[0].distance, 0);
    clamped |= w.Heard(receiver)[0].distance == 0;
  }
  EXPECT_TRUE(clamped);
}

// Two senders that hear each other, with messages longer than the step:
// whenever both queue, the later start finds the channel busy and defers.
TEST(IrMessagingTest, CarrierSenseLetsOneOfTwoOverlappingSendersOut) {
  IrWorld w;
  IrSettings s = Exact();
  s.packet_time = 1;  // longer than the step: every two messages of a step overlap
  const ObjectId a = w.Robot(0, 0, s);
  const ObjectId b = w.Robot(0.05, 0, s);
  const ObjectId listener = w.Robot(0.025, 0.03, s);
  int a_won = 0, b_won = 0;
  for (int i = 0; i < 60; ++i) {
    w.Send(a, "a");
    w.Send(b, "b");
    w.Step();
    ASSERT_NE(w.Sent(a), w.Sent(b)) << "step " << i;
    (w.Sent(a) ? a_won : b_won) += 1;
    // The listener hears the one that went out, whole.
    const std::vector<HeardMessage> heard = w.Heard(listener);
    ASSERT_EQ(heard.size(), 1u);
    EXPECT_EQ(heard[0].data, w.Sent(a) ? "a" : "b");
    // The one that deferred heard the other (it was listening).
    EXPECT_EQ(w.Heard(w.Sent(a) ? b : a).size(), 1u);
  }
  // Each wins about half the time (the start times are random).
  EXPECT_GT(a_won, 10);
  EXPECT_GT(b_won, 10);
}

TEST(IrMessagingTest, WithoutCarrierSenseBothGoOutAndCollide) {
  IrWorld w;
  IrSettings s = Exact();
  s.packet_time = 1;
  s.carrier_sense = false;
  const ObjectId a = w.Robot(0, 0, s);
  const ObjectId b = w.Robot(0.05, 0, s);
  const ObjectId listener = w.Robot(0.025, 0.03, s);
  w.Send(a, "a");
  w.Send(b, "b");
  w.Step();
  EXPECT_TRUE(w.Sent(a));
  EXPECT_TRUE(w.Sent(b));
  EXPECT_TRUE(w.Heard(listener).empty());  // both lost there
  EXPECT_TRUE(w.Heard(a).empty());         // each was sending: half duplex
}

// Short messages rarely overlap: in most steps both go out, one after the
// other, and each hears the other.
TEST(IrMessagingTest, ShortMessagesOfTwoSendersUsuallyBothGoOut) {
  IrWorld w;
  IrSettings s = Exact();
  s.packet_time = 1e-5;
  const ObjectId a = w.Robot(0, 0, s);
  const ObjectId b = w.Robot(0.05, 0, s);
  int both = 0;
  for (int i = 0; i < 50; ++i) {
    w.Send(a, "a");
    w.Send(b, "b");
    w.Step();
    if (!w.Sent(a) || !w.Sent(b)) continue;
    ++both;
    ASSERT_EQ(w.Heard(a).size(), 1u);
    EXPECT_EQ(w.Heard(a)[0].data, "b");
    ASSERT_EQ(w.Heard(b).size(), 1u);
    EXPECT_EQ(w.Heard(b)[0].data, "a");
  }
  EXPECT_GE(both, 45);
}

// A and C cannot hear each other (0.16 m apart); B, between them, hears both.
struct HiddenTerminal {
  IrWorld w;
  ObjectId a, b, c;
  explicit HiddenTerminal(const IrSettings& s) {
    a = w.Robot(-0.08, 0, s);
    b = w.Robot(0, 0, s);
    c = w.Robot(0.08, 0, s);
  }
  std::vector<HeardMessage> Step() {
    w.Send(a, "from a");
    w.Send(c, "from c");
    w.Step();
    return w.Heard(b);
  }
};

TEST(IrMessagingTest, HiddenTerminalsCollideAtTheReceiverBetweenThem) {
  IrSettings s = Exact();
  s.packet_time = 1;  // every two messages of a step overlap
  HiddenTerminal t(s);
  for (int i = 0; i < 10; ++i) {
    EXPECT_TRUE(t.Step().empty());
    // Carrier sense cannot help: neither hears the other, both went out.
    EXPECT_TRUE(t.w.Sent(t.a));
    EXPECT_TRUE(t.w.Sent(t.c));
  }
}

TEST(IrMessagingTest, HiddenTerminalsThatDoNotOverlapAreBothHeardInStartOrder) {
  IrSettings s = Exact();
  s.packet_time = 1e-9;  // never overlap (in practice)
  HiddenTerminal t(s);
  bool a_first = false, c_first = false;
  for (int i = 0; i < 20; ++i) {
    const std::vector<HeardMessage> heard = t.Step();
    ASSERT_EQ(heard.size(), 2u);
    EXPECT_NE(heard[0].data, heard[1].data);
    (heard[0].data == "from a" ? a_first : c_first) = true;
    EXPECT_NEAR(heard[0].distance, 0.08, 1e-12);
  }
  EXPECT_TRUE(a_first && c_first);  // arrival order follows the random start times
}

TEST(IrMessagingTest, WithoutCollisionsOverlappingMessagesAreBothHeard) {
  IrSettings s = Exact();
  s.packet_time = 1;
  s.collisions = false;
  HiddenTerminal t(s);
  EXPECT_EQ(t.Step().size(), 2u);
}

TEST(IrMessagingTest, LossAndFailureDropMessagesAtTheirRates) {
  IrWorld w;
  IrSettings lossy = Exact();
  lossy.loss_probability = 0.3;
  IrSettings failing = Exact();
  failing.failure_probability = 0.6;
  const ObjectId sender = w.Robot(0, 0, Exact());
  const ObjectId r1 = w.Robot(0.05, 0, lossy);
  const ObjectId r2 = w.Robot(-0.05, 0, failing);
  const int n = 2000;
  int heard1 = 0, heard2 = 0;
  for (int i = 0; i < n; ++i) {
    w.Send(sender, "x");
    w.Step();
    heard1 += static_cast<int>(w.Heard(r1).size());
    heard2 += static_cast<int>(w.Heard(r2).size());
  }
  // Binomial: within 4 standard deviations.
  EXPECT_NEAR(heard1, 0.7 * n, 4 * std::sqrt(n * 0.3 * 0.7));
  EXPECT_NEAR(heard2, 0.4 * n, 4 * std::sqrt(n * 0.6 * 0.4));
}

// A lattice of Kilobots 5 cm apart, about one in 16 queuing a message each
// step (every 0.5 s at 1/32 s steps): the state hash (what each sent and
// heard) after 40 steps at 1 and 2 threads.
uint64_t LatticeRun(int threads, int* heard, int* deferred) {
  IrWorld w(threads, 3);
  IrSettings s;  // the Kilobot's, with noise
  s.loss_probability = 0.05;
  std::vector<ObjectId> ir;
  for (int i = 0; i < 500; ++i) ir.push_back(w.Robot(0.05 * (i % 25), 0.05 * (i / 25), s));
  Rng rng(11, 0);
  *heard = *deferred = 0;
  for (int step = 0; step < 40; ++step) {
    std::vector<ObjectId> queued;
    for (ObjectId id : ir)
      if (rng.Uniform() < 1.0 / 16) {
        w.Send(id, std::string(12, static_cast<char>(step)));
        queued.push_back(id);
      }
    w.Step();
    for (ObjectId id : queued) *deferred += w.Sent(id) ? 0 : 1;
    for (ObjectId id : ir) *heard += static_cast<int>(w.Heard(id).size());
  }
  return w.world().StateHash();
}

TEST(IrMessagingTest, SameResultsAtOneAndTwoThreads) {
  int heard1 = 0, deferred1 = 0, heard2 = 0, deferred2 = 0;
  const uint64_t one = LatticeRun(1, &heard1, &deferred1);
  const uint64_t two = LatticeRun(2, &heard2, &deferred2);
  EXPECT_EQ(one, two);
  EXPECT_EQ(heard1, heard2);
  EXPECT_EQ(deferred1, deferred2);
  // Not a trivial run: messages were heard and some senders deferred.
  EXPECT_GT(heard1, 1000);
  EXPECT_GT(deferred1, 0);
}

}  // namespace
}  // namespace swarmsim::ir_messaging
