// The state hash (framework/state_hash.cc, World::StateHash): what `--hash`
// prints and tests/data/golden_hashes.tsv compares, so a run can be checked
// against another bit for bit.
#include "framework/state_hash.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"
#include "tests/framework/script_world.h"

namespace swarmsim {
namespace {

using namespace script_test;  // script_world.h

using testing::ErrorOf;

// The hash is of the bytes added, not of how they were cut into calls:
// the World adds arrays whole or value by value as suits each part.
TEST(StateHasherTest, TheDigestDependsOnTheBytesNotOnHowTheyWereAdded) {
  const double values[] = {1.5, -2.25, 1e300, 0.0};
  StateHasher whole;
  whole.Add(values, sizeof values);
  StateHasher pieces;
  for (double v : values) pieces.AddValue(v);
  EXPECT_EQ(whole.Digest(), pieces.Digest());
  // Reading the digest does not end the hash: the same value again, and more
  // bytes still count.
  EXPECT_EQ(whole.Digest(), pieces.Digest());
  const uint64_t before = pieces.Digest();
  pieces.AddValue(0.0);
  EXPECT_NE(pieces.Digest(), before);
}

// Values are gathered a few KiB at a time before XXH3 sees them: arrays
// longer than that, values across its edge, and a digest read halfway give
// what one call over all the bytes gives.
TEST(StateHasherTest, ManySmallValuesHashAsTheirBytesInOneCall) {
  std::vector<uint64_t> values(5000);
  for (size_t i = 0; i < values.size(); ++i) values[i] = i * 0x9e3779b97f4a7c15ULL;
  StateHasher whole;
  whole.Add(values.data(), values.size() * sizeof(uint64_t));  // one call, longer than the buffer
  StateHasher one_by_one;
  for (uint64_t v : values) one_by_one.AddValue(v);
  EXPECT_EQ(one_by_one.Digest(), whole.Digest());
  StateHasher mixed;  // odd sizes, a long run in the middle, a digest read halfway
  const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
  const size_t total = values.size() * sizeof(uint64_t);
  size_t at = 0;
  for (size_t cut : {size_t{3}, size_t{4093}, size_t{7}, size_t{9000}, size_t{1}}) {
    mixed.Add(bytes + at, cut);
    at += cut;
    (void)mixed.Digest();
  }
  mixed.Add(bytes + at, total - at);
  EXPECT_EQ(mixed.Digest(), whole.Digest());
  // A byte changed anywhere, even one still gathered, changes the digest.
  values.back() ^= 1;
  StateHasher changed;
  for (uint64_t v : values) changed.AddValue(v);
  EXPECT_NE(changed.Digest(), whole.Digest());
}

TEST(StateHasherTest, OrderSignAndEveryBitChangeTheDigest) {
  const auto digest = [](std::initializer_list<double> values) {
    StateHasher h;
    for (double v : values) h.AddValue(v);
    return h.Digest();
  };
  const uint64_t base = digest({1, 2});
  EXPECT_EQ(digest({1, 2}), base);
  EXPECT_NE(digest({2, 1}), base);
  EXPECT_NE(digest({1, -2}), base);
  EXPECT_NE(digest({1, std::nextafter(2.0, 3.0)}), base);  // one ulp
  // -0 and +0 compare equal but are different states (1/x differs).
  EXPECT_NE(digest({0.0}), digest({-0.0}));
  // Nothing added is a hash too, and not that of a zero byte.
  StateHasher empty;
  StateHasher zero;
  zero.AddValue(uint8_t{0});
  EXPECT_NE(empty.Digest(), zero.Digest());
}

TEST(StateHasherTest, HexIsSixteenLowercaseDigitsWithLeadingZeros) {
  EXPECT_EQ(StateHasher::ToHex(0), "0000000000000000");
  EXPECT_EQ(StateHasher::ToHex(0x1f), "000000000000001f");
  EXPECT_EQ(StateHasher::ToHex(0xDEADBEEF00000001ull), "deadbeef00000001");
  EXPECT_EQ(StateHasher::ToHex(std::numeric_limits<uint64_t>::max()), "ffffffffffffffff");
}

// Two worlds built alike hash alike; moving one object by a nanometre, or
// stepping once more, changes the hash.
TEST(StateHasherTest, TheWorldHashFollowsPosesAndSteps) {
  const auto hash = [](double x, int steps) {
    ScriptWorld w;
    w.AddRobot("bot#0", "", x, 0);
    w.Steps(steps);
    return w.world().StateHash();
  };
  const uint64_t base = hash(1, 2);
  EXPECT_EQ(hash(1, 2), base);
  EXPECT_NE(hash(1 + 1e-9, 2), base);
  EXPECT_NE(hash(1, 3), base);
}

TEST(ScriptControlTest, StateHashCoversWhatScriptsLeaveForTheNextStep) {
  // Identical worlds except for what a script leaves pending at the end of a
  // step: a signal, an undelivered message, a custom data block. Each changes
  // the future, so each must change the hash.
  auto hash_after = [](const std::string& action) {
    ScriptWorld w;
    w.AddRobot("bot#0", "function sysCall_actuation() " + action + " end");
    w.Steps(2);
    return w.world().StateHash();
  };
  const uint64_t nothing = hash_after("");
  EXPECT_EQ(hash_after(""), nothing);
  EXPECT_NE(hash_after("sim.setSignal('s', 1)"), nothing);
  EXPECT_NE(hash_after("sim.sendGlobalMessage('hi')"), nothing);
  EXPECT_NE(hash_after("sim.writeCustomDataBlock(sim.getObject('.'), 't', 'x')"), nothing);
}

}  // namespace
}  // namespace swarmsim
