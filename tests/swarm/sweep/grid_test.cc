// Sweep grids (swarm/sweep/grid.cc): parameter specs, seeds and their
// cartesian product, and malformed seeds named by the program.
#include "swarm/sweep/grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "tests/swarm/run_program.h"
#include "tests/swarm/sweep/sweep_db.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;
using sweep_testing::kWorld;
using sweep_testing::TempDir;

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
  // One number spelled two ways is the same runs twice (QA: 1.0,1,1e0 made 3).
  try {
    ParseParamSpec("k=1.0,2,1e0");
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "--param k=1.0,2,1e0: value '1e0' appears twice (as '1.0')");
  }
  EXPECT_EQ(ParseParamSpec("mode=a,b,1,01x").values.size(), 4u);  // words stay words
}

TEST(SweepGridTest, Seeds) {
  EXPECT_EQ(ParseSeeds("3"), (std::vector<uint64_t>{1, 2, 3}));
  EXPECT_EQ(ParseSeeds("5-8"), (std::vector<uint64_t>{5, 6, 7, 8}));
  EXPECT_EQ(ParseSeeds("1-20").size(), 20u);
  EXPECT_EQ(ParseSeeds("11,3,7"), (std::vector<uint64_t>{11, 3, 7}));
  for (const char* bad : {"0", "x", "8-5", "1,1", "-3", "1.5"})
    EXPECT_THROW(ParseSeeds(bad), Error) << bad;
  // A range up to the last seed ends there (QA: it ran on past 2^64 - 1 and
  // took 16 GB).
  EXPECT_EQ(ParseSeeds("18446744073709551614-18446744073709551615"),
            (std::vector<uint64_t>{18446744073709551614u, 18446744073709551615u}));
  EXPECT_EQ(ParseSeeds("18446744073709551615-18446744073709551615").size(), 1u);
}

// More than a million runs in all is refused with the grid's shape, before
// anything is listed (QA: two parameters of 10^6 values were a bad_alloc).
TEST(SweepGridTest, AGridOfMoreThanAMillionRunsIsRefused) {
  const std::vector<ParamSpec> big = {ParseParamSpec("k=1:2:1000000"),
                                      ParseParamSpec("work=1:2:1000000")};
  try {
    ExpandGrid(big, {1});
    ADD_FAILURE() << "not refused";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "the sweep would have more than 10^6 runs (1000000 values of k x 1000000 values "
                 "of work x 1 seeds): sweep fewer values, or split it into several sweeps");
  }
  EXPECT_THROW(ExpandGrid({ParseParamSpec("k=1:2:1000")}, ParseSeeds("1001")), Error);
  EXPECT_EQ(ExpandGrid({ParseParamSpec("k=1:2:1000")}, ParseSeeds("1000")).size(), 1000000u);
  try {
    ParseParamSpec("k=1:2:1000001");
    ADD_FAILURE() << "not refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("from 1 to 10^6"), std::string::npos) << e.what();
  }
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

TEST(SweepTest, MalformedSeedsAreClearErrorsNamingTheOptionAndTheValue) {
  const fs::path dir = TempDir("seeds");
  const fs::path db = dir / "r.db";
  // --seeds SPEC -> what the message must say after "error: --seeds SPEC: ".
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"18446744073709551616",
       "the number of seeds K must be 1 to 10^6, got '18446744073709551616'"},
      {"1-18446744073709551616",
       "'18446744073709551616' is not a seed (a whole number from 0 to 18446744073709551615)"},
      {"5-3", "a seed range A-B needs A <= B (got 5 > 3)"},
      {"1,,2", "empty seed in the list"},
      {"-1", "'-1' is not a seed (a whole number from 0 to 18446744073709551615)"},
      {"1.5", "expected K (seeds 1..K), a range A-B or a list A,B,C, got '1.5'"},
  };
  for (const auto& [spec, message] : cases) {
    Result r = RunProgram("sweep " + kWorld + " --seeds " + spec + " --steps 1 --quiet --db " +
                          db.string());
    EXPECT_EQ(r.exit_code, 2) << spec << ": " << r.output;
    EXPECT_NE(r.output.find("error: --seeds " + spec + ": " + message), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(db)) << spec;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
