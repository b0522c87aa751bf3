// framework/memory_forecast.cc: sizes as users write them, the room the
// process has, and the forecast that refuses what will not fit.
#include "framework/memory_forecast.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace swarmsim {
namespace {

constexpr uint64_t kMiB = uint64_t{1} << 20;
constexpr uint64_t kGiB = uint64_t{1} << 30;

TEST(MemoryForecastTest, SizesReadAsUsersWriteThem) {
  uint64_t bytes = 0;
  ASSERT_TRUE(ParseMemorySize("500M", &bytes));
  EXPECT_EQ(bytes, 500 * kMiB);
  ASSERT_TRUE(ParseMemorySize("2G", &bytes));
  EXPECT_EQ(bytes, 2 * kGiB);
  ASSERT_TRUE(ParseMemorySize("1.5GiB", &bytes));
  EXPECT_EQ(bytes, 3 * kGiB / 2);
  ASSERT_TRUE(ParseMemorySize("8g", &bytes));
  EXPECT_EQ(bytes, 8 * kGiB);
  ASSERT_TRUE(ParseMemorySize("4096", &bytes));
  EXPECT_EQ(bytes, 4096u);
  for (const char* bad : {"", "abc", "-1G", "2X", "0", " 5G", "5 G", "nan", "1e30T"})
    EXPECT_FALSE(ParseMemorySize(bad, &bytes)) << bad;
  EXPECT_EQ(FormatSize(1536), "1.5 KiB");
  EXPECT_EQ(FormatSize(300.0 * kMiB), "300 MiB");
  EXPECT_EQ(FormatSize(512), "512 bytes");
  EXPECT_EQ(GroupThousands(1234567), "1,234,567");
  EXPECT_EQ(GroupThousands(999), "999");
  EXPECT_EQ(GroupThousands(100000), "100,000");
  for (const char* off : {"0", "off", "OFF", "false", "No"}) EXPECT_TRUE(IsOffValue(off)) << off;
  for (const char* on : {"1", "on", "", "yes"}) EXPECT_FALSE(IsOffValue(on)) << on;
  EXPECT_FALSE(IsOffValue(nullptr));
  for (const char* on : {"1", "On", "TRUE", "yes"}) EXPECT_TRUE(IsOnValue(on)) << on;
  for (const char* other : {"0", "off", "", "maybe"}) EXPECT_FALSE(IsOnValue(other)) << other;
  EXPECT_FALSE(IsOnValue(nullptr));
}

TEST(MemoryForecastTest, TheRoomIsTheSmallestOfMachineCgroupAndCap) {
  const MemoryRoom machine = ReadMemoryRoom(0);
  EXPECT_GT(machine.resident, 0u);
  ASSERT_NE(machine.available, UINT64_MAX) << "Linux has /proc/meminfo";
  EXPECT_GT(machine.available, 0u);
  EXPECT_FALSE(machine.bound.empty());
  // A cap 64 MiB above what the process holds leaves at most that.
  const MemoryRoom capped = ReadMemoryRoom(machine.resident + 64 * kMiB);
  EXPECT_LE(capped.available, 64 * kMiB);
  EXPECT_GT(capped.available, 32 * kMiB);
  EXPECT_NE(capped.bound.find("--max-memory"), std::string::npos) << capped.bound;
  // A cap below what the process holds leaves nothing.
  EXPECT_EQ(ReadMemoryRoom(1).available, 0u);
}

TEST(MemoryForecastTest, TheVerdictSaysWhatTheRestNeedsAndHowManyFit) {
  MemoryRoom room;
  room.available = 8 * kGiB;
  room.bound = "this machine's available memory and swap";
  // 10,240 items took 160 MiB: 16 KiB each; 980,000 more need ~15 GiB.
  const std::string no =
      MemoryForecast::Verdict("robots' Lua states", 1'000'000, 20'000, 10'240, 160 * kMiB, room);
  EXPECT_NE(no.find("not enough memory for 1,000,000 robots' Lua states"), std::string::npos) << no;
  EXPECT_NE(no.find("the last 10,240 took 160 MiB (16.0 KiB each)"), std::string::npos) << no;
  EXPECT_NE(no.find("the other 980,000 need about 15.0 GiB more"), std::string::npos) << no;
  EXPECT_NE(no.find("may take 8.0 GiB more (this machine's"), std::string::npos) << no;
  EXPECT_NE(no.find("About 544,288 would fit"), std::string::npos)
      << no;  // 20,000 + 8 GiB / 16 KiB
  EXPECT_NE(no.find("SWARMSIM_MEMORY_CHECK=0"), std::string::npos) << no;
  // With 16 GiB the rest fits; with the room unknown nothing is said.
  room.available = 16 * kGiB;
  EXPECT_EQ(
      MemoryForecast::Verdict("robots' Lua states", 1'000'000, 20'000, 10'240, 160 * kMiB, room),
      "");
  room.available = UINT64_MAX;
  EXPECT_EQ(MemoryForecast::Verdict("robot copies", 1'000'000, 20'000, 10'240, 160 * kMiB, room),
            "");
  // Past the room already (a cap below what the built ones hold): said so,
  // and fewer than those built would fit, not "about" them.
  room.available = 0;
  room.resident = 900 * kMiB;
  room.bound = "--max-memory 500 MiB";
  const std::string past =
      MemoryForecast::Verdict("robots' Lua states", 30'000, 20'000, 10'240, 160 * kMiB, room);
  EXPECT_NE(past.find("the process holds 900 MiB already, with no room left (--max-memory 500 "
                      "MiB). Fewer than 20,000 would fit"),
            std::string::npos)
      << past;
  EXPECT_EQ(past.find("About"), std::string::npos) << past;
}

// Arrays reserved for every item, about to be populated at once, are
// checked before anything is built: refused past the room (naming it),
// fine within it, and under the same rules as the checkpoints (a small
// world, the check off: nothing).
TEST(MemoryForecastTest, ReservedArraysPastTheRoomAreRefusedBeforeAnythingIsBuilt) {
  const uint64_t cap = ReadMemoryRoom(0).resident + 64 * kMiB;
  const MemoryForecast forecast("robot copies", 100'000, cap);
  const std::string no = forecast.Reserved(kGiB);
  EXPECT_NE(no.find("not enough memory for 100,000 robot copies: the arrays reserved for them "
                    "take 1.0 GiB (10.5 KiB each) before anything else"),
            std::string::npos)
      << no;
  EXPECT_NE(no.find("(--max-memory "), std::string::npos) << no;
  EXPECT_NE(no.find("Fewer than "), std::string::npos) << no;
  EXPECT_EQ(forecast.Reserved(16 * kMiB), "");
  // A cap below what the program holds before any copy: no "fewer than 0".
  const std::string none = MemoryForecast("robot copies", 100'000, 4096).Reserved(kGiB);
  EXPECT_NE(none.find("already, with no room left (--max-memory 4.0 KiB). Give the run more "
                      "memory"),
            std::string::npos)
      << none;
  EXPECT_EQ(none.find("Fewer than"), std::string::npos) << none;
  EXPECT_EQ(MemoryForecast("robot copies", 1'000, cap).Reserved(kGiB), "") << "a small world";
  setenv("SWARMSIM_MEMORY_CHECK", "0", 1);
  const MemoryForecast off("robot copies", 100'000, cap);
  unsetenv("SWARMSIM_MEMORY_CHECK");
  EXPECT_EQ(off.Reserved(kGiB), "");
}

// Items that each take 64 KiB, under a cap 64 MiB above the start: the
// forecast refuses them (once); without a cap, in a small world, or with
// the check turned off, it says nothing.
std::string BuildUnder(uint64_t cap, int64_t total, int* refusals, int64_t* refused_at) {
  MemoryForecast forecast("test items", total, cap);
  std::vector<std::unique_ptr<char[]>> held;
  std::string first;
  for (int64_t built = 1; built < total; ++built) {
    held.emplace_back(new char[64 * 1024]);
    for (size_t i = 0; i < 64 * 1024; i += 4096) held.back()[i] = 1;  // resident
    std::string why = forecast.Built(built);
    if (why.empty()) continue;
    ++*refusals;
    if (first.empty()) {
      first = why;
      *refused_at = built;
      // The caller stops here; a few more show it is said once.
      if (built + 5 >= total) break;
      total = built + 5;
    }
  }
  return first;
}

TEST(MemoryForecastTest, ItemsThatWillNotFitAreRefusedEarlyAndOnce) {
  const uint64_t start = ReadMemoryRoom(0).resident;
  int refusals = 0;
  int64_t at = 0;
  const std::string why = BuildUnder(start + 64 * kMiB, 4000, &refusals, &at);
  EXPECT_EQ(refusals, 1);
  EXPECT_NE(why.find("not enough memory for 4,000 test items"), std::string::npos) << why;
  EXPECT_NE(why.find("--max-memory"), std::string::npos) << why;
  // 4,000 x 64 KiB = 250 MiB against 64 MiB: growth is measured from the
  // first checkpoint (1,000 items), the verdict comes at the next (2,000).
  EXPECT_EQ(at, 2000);

  refusals = 0;
  EXPECT_EQ(BuildUnder(0, 3000, &refusals, &at), "");  // the machine has 200 MiB
  EXPECT_EQ(refusals, 0);
  EXPECT_EQ(BuildUnder(start + 64 * kMiB, 1999, &refusals, &at), "") << "small worlds pass";
  setenv("SWARMSIM_MEMORY_CHECK", "off", 1);
  EXPECT_EQ(BuildUnder(start + 64 * kMiB, 4000, &refusals, &at), "");
  unsetenv("SWARMSIM_MEMORY_CHECK");
  EXPECT_EQ(refusals, 0);
}

// A world's start (physics, each module, the scripts) is checked after each
// stage: one that took the process past its cap stops it, naming the stage.
TEST(MemoryForecastTest, AStartStagePastTheCapIsNamed) {
  const uint64_t tiny = 1;  // below what the program holds: no room left
  const std::string why = NoRoomLeft(100000, "starting module proximity", tiny);
  EXPECT_NE(why.find("not enough memory for 100,000 robots: after starting module proximity the "
                     "process holds "),
            std::string::npos)
      << why;
  EXPECT_NE(why.find(", with no room left (--max-memory 1 bytes)"), std::string::npos) << why;
  EXPECT_NE(why.find("SWARMSIM_MEMORY_CHECK=0"), std::string::npos) << why;
  EXPECT_EQ(NoRoomLeft(100000, "starting module proximity", 0), "") << "no cap: the machine's room";
  EXPECT_EQ(NoRoomLeft(1999, "starting physics", tiny), "") << "small worlds pass";
  setenv("SWARMSIM_MEMORY_CHECK", "no", 1);
  EXPECT_EQ(NoRoomLeft(100000, "starting physics", tiny), "");
  unsetenv("SWARMSIM_MEMORY_CHECK");
}

}  // namespace
}  // namespace swarmsim
