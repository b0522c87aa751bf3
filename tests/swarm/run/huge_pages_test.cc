// swarm/run/huge_pages.cc: the program restarts itself once with glibc's
// malloc asked for transparent huge pages, and summary.json says whether it
// was; SWARMSIM_HUGEPAGES=0 turns it off, and a user's own GLIBC_TUNABLES
// still apply.
#include "swarm/run/huge_pages.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

nlohmann::json RunAndReadSummary(const std::string& environment, const std::string& name) {
  const fs::path out = swarmsim::testing::FreshTempDir("swarmsim_huge_pages", name);
  const auto r = swarmsim::testing::RunCommand(environment + " " + SWARMSIM_BINARY + " run " +
                                               swarmsim::testing::CliData("ok.yaml") +
                                               " --steps 2 --quiet --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream file(out / "summary.json");
  EXPECT_TRUE(file.good()) << out;
  return file.good() ? nlohmann::json::parse(file) : nlohmann::json::object();
}

TEST(HugePagesTest, RunsAskForHugePagesUnlessTurnedOff) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "malloc is ASan's: the glibc tunable does not apply";
#endif
  EXPECT_EQ(RunAndReadSummary("", "default")["huge_pages"], true);
  EXPECT_EQ(RunAndReadSummary("SWARMSIM_HUGEPAGES=0", "off")["huge_pages"], false);
  EXPECT_EQ(RunAndReadSummary("SWARMSIM_HUGEPAGES=Off", "off_word")["huge_pages"], false);
  // A user's tunables are kept beside it, and a user's own choice wins.
  EXPECT_EQ(RunAndReadSummary("GLIBC_TUNABLES=glibc.malloc.arena_max=2", "merged")["huge_pages"],
            true);
  EXPECT_EQ(RunAndReadSummary("GLIBC_TUNABLES=glibc.malloc.hugetlb=0", "user")["huge_pages"],
            false);
  // The restart keeps the arguments and the exit code of a failing run.
  const auto bad = swarmsim::testing::RunProgram("run no_such_world.yaml --steps 1");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("no_such_world.yaml"), std::string::npos) << bad.output;
}

// The value the restart sets: the user's tunables kept, ours added once,
// theirs winning when they name it.
TEST(HugePagesTest, TheUsersTunablesAreKeptAndTheirHugetlbWins) {
  using swarmsim::TunablesWithHugePages;
  EXPECT_EQ(TunablesWithHugePages(nullptr), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(TunablesWithHugePages(""), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(TunablesWithHugePages("glibc.malloc.arena_max=2"),
            "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
  EXPECT_EQ(TunablesWithHugePages("glibc.malloc.hugetlb=0"), "");
  EXPECT_EQ(TunablesWithHugePages("glibc.malloc.check=0:glibc.malloc.hugetlb=2"), "");
  for (const char* off : {"0", "off", "OFF", "false", "no"})
    EXPECT_TRUE(swarmsim::HugePagesTurnedOff(off)) << off;
  for (const char* on : {"1", "on", "yes", ""})
    EXPECT_FALSE(swarmsim::HugePagesTurnedOff(on)) << on;
  EXPECT_FALSE(swarmsim::HugePagesTurnedOff(nullptr));
  // A value that is neither is said, once (not again by the restarted process).
  for (const char* clear : {"0", "off", "YES", "True", "1", "", static_cast<const char*>(nullptr)})
    EXPECT_FALSE(swarmsim::HugePagesValueUnclear(clear)) << (clear ? clear : "(unset)");
  EXPECT_TRUE(swarmsim::HugePagesValueUnclear("maybe"));
#if !defined(__SANITIZE_ADDRESS__)
  const auto r = swarmsim::testing::RunCommand(
      std::string("SWARMSIM_HUGEPAGES=maybe ") + SWARMSIM_BINARY + " run " +
      swarmsim::testing::CliData("ok.yaml") + " --steps 1 --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const std::string warning = "warning: SWARMSIM_HUGEPAGES='maybe' is neither 0, off, false, no";
  const size_t at = r.output.find(warning);
  EXPECT_NE(at, std::string::npos) << r.output;
  EXPECT_EQ(r.output.find(warning, at + 1), std::string::npos) << "said once: " << r.output;
#endif
}

}  // namespace
