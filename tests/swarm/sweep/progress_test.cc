// Progress of a sweep (swarm/sweep/progress.cc): plain lines every 5% and at
// every failure when not on a terminal, a bar redrawn in place on one; runs
// finished before this session count as done.
#include "swarm/sweep/progress.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "tests/text_lines.h"

namespace swarmsim {
namespace {

std::vector<std::string> Lines(const std::string& text) {
  return swarmsim::testing::TextLines(text);
}

TEST(SweepProgressTest, PlainLinesEveryFivePercentAndAtEachFailure) {
  std::ostringstream out;
  SweepProgress progress(out, 40, 0, 0, /*tty=*/false, /*enabled=*/true);
  for (int64_t id = 1; id <= 40; ++id) progress.RunEnded(id, id != 7, "boom", 2);
  progress.Finish();
  EXPECT_EQ(progress.done(), 40);
  EXPECT_EQ(progress.failed(), 1);
  const std::vector<std::string> lines = Lines(out.str());
  // A line for the first run and each further 5% (runs 1, 2, 4, 6, 8, ...
  // 40: 21 lines), and for the failure its own line and a count line.
  ASSERT_EQ(lines.size(), 23u) << out.str();
  EXPECT_EQ(lines[0].rfind("1/40 runs  0 failed  39 left  2 running  elapsed ", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find("  ETA "), std::string::npos) << lines[0];
  EXPECT_EQ(lines[3].rfind("6/40 runs  0 failed  34 left  ", 0), 0u) << lines[3];
  EXPECT_EQ(lines[4], "run 7 failed: boom");
  EXPECT_EQ(lines[5].rfind("7/40 runs  1 failed  33 left  ", 0), 0u) << lines[5];
  EXPECT_EQ(lines[6].rfind("8/40 runs  1 failed  32 left  ", 0), 0u) << lines[6];
  EXPECT_EQ(lines.back().rfind("40/40 runs  1 failed  0 left  2 running  elapsed ", 0), 0u)
      << lines.back();
  EXPECT_EQ(lines.back().find("ETA"), std::string::npos) << "nothing left: no ETA";
  EXPECT_EQ(out.str().find('\r'), std::string::npos) << "no terminal codes in a log";
}

TEST(SweepProgressTest, RunsFinishedBeforeCountAsDone) {
  std::ostringstream out;
  SweepProgress progress(out, 10, 6, /*already_failed=*/2, /*tty=*/false, /*enabled=*/true);
  progress.RunEnded(7, true, "", 1);
  EXPECT_EQ(progress.done(), 1) << "this session's";
  EXPECT_EQ(Lines(out.str()).back().rfind("7/10 runs  2 failed  3 left  1 running", 0), 0u)
      << "the failures of before count too: " << out.str();
  progress.RunEnded(8, false, "boom", 0);
  EXPECT_EQ(Lines(out.str()).back().rfind("8/10 runs  3 failed  2 left", 0), 0u) << out.str();
}

TEST(SweepProgressTest, ATerminalGetsABarRedrawnInPlace) {
  std::ostringstream out;
  SweepProgress progress(out, 3, 0, 0, /*tty=*/true, /*enabled=*/true);
  progress.RunEnded(1, false, "crashed", 1);  // a failure draws at once
  const std::string text = out.str();
  EXPECT_EQ(text.rfind("\r\033[Krun 1 failed: crashed\n\r\033[K[" + std::string(10, '#') +
                           std::string(20, ' ') + "] 1/3 runs  1 failed  2 left  1 running",
                       0),
            0u)
      << text;
  EXPECT_EQ(text.find("\n", text.find("] 1/3")), std::string::npos) << "the bar stays on its line";
  progress.Finish();
  EXPECT_EQ(out.str().back(), '\n');
}

TEST(SweepProgressTest, QuietPrintsNothingButCounts) {
  std::ostringstream out;
  SweepProgress progress(out, 5, 0, 0, /*tty=*/false, /*enabled=*/false);
  progress.RunEnded(1, false, "boom", 1);
  progress.RunEnded(2, true, "", 1);
  progress.Finish();
  EXPECT_EQ(out.str(), "");
  EXPECT_EQ(progress.done(), 2);
  EXPECT_EQ(progress.failed(), 1);
}

}  // namespace
}  // namespace swarmsim
