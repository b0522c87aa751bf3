// swarm/run/step_progress.h: the progress of a run's steps. Its ETA and
// real-time factor are of the steps alone (a million robots' 10 s start
// made the first line's ETA 107 s for a 27 s rest) and of this run's
// simulated time (a resumed run counted the saved run's), and a factor
// below 1 keeps two significant digits (a million robots ran at "0.0x").
#include "swarm/run/step_progress.h"

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

TEST(StepProgressTest, EtaAndFactorAreOfTheStepsAloneNotTheStart) {
  std::ostringstream out;
  StepProgress progress(out, 10, /*enabled=*/true, /*tty=*/false, nullptr);
  // The world took 10 s to start; then each 0.1 s step takes 3 s.
  progress.Begin(/*sim_time=*/0.0, /*wall=*/10.0);
  for (int i = 1; i <= 10; ++i) progress.Update(i, 0.1 * i, 10.0 + 3.0 * i);
  const auto lines = Lines(out.str());
  ASSERT_EQ(lines.size(), 10u) << out.str();
  // After 1 of 10 steps: 9 steps of 3 s are left (with the start in it: 117 s).
  EXPECT_NE(lines[0].find(" 10%  step 1/10  sim 0.1 s  0.033x real time  ETA 27.0 s"),
            std::string::npos)
      << lines[0];
  EXPECT_NE(lines[9].find("100%  step 10/10  sim 1.0 s  0.033x real time  ETA 0.0 s"),
            std::string::npos)
      << lines[9];
}

TEST(StepProgressTest, AResumedRunsFactorIsOfItsOwnSteps) {
  std::ostringstream out;
  StepProgress progress(out, 2, true, false, [] { return std::string("run 3 of 20"); });
  // Resumed at 12 s of simulated time; two 0.1 s steps in 0.1 s each.
  progress.Begin(12.0, 0.5);
  progress.Update(1, 12.1, 0.6);
  progress.Update(2, 12.2, 0.7);
  const auto lines = Lines(out.str());
  ASSERT_EQ(lines.size(), 2u) << out.str();
  EXPECT_NE(lines[1].find("sim 12.2 s  1.0x real time  ETA 0.0 s  run 3 of 20"), std::string::npos)
      << lines[1];
}

TEST(StepProgressTest, PlainLinesEveryTenthATerminalBarAtMostEveryTenthOfASecond) {
  std::ostringstream plain;
  StepProgress lines(plain, 100, true, false, nullptr);
  lines.Begin(0, 0);
  for (int i = 1; i <= 100; ++i) lines.Update(i, 0.1 * i, 0.001 * i);
  // The first step's line (the rate is known early), then one each 10%.
  EXPECT_EQ(Lines(plain.str()).size(), 11u) << plain.str();

  std::ostringstream bar;
  StepProgress tty(bar, 100, true, true, nullptr);
  tty.Begin(0, 0);
  for (int i = 1; i <= 100; ++i) tty.Update(i, 0.1 * i, 0.01 * i);  // 1 s in all
  tty.Finish();
  const std::string text = bar.str();
  size_t redraws = 0;
  for (char c : text) redraws += c == '\r';
  EXPECT_GE(redraws, 9u) << text;  // the first, then one each 0.1 s, and the last
  EXPECT_LE(redraws, 12u) << text;
  EXPECT_NE(text.find("[##############################] 100%"), std::string::npos) << text;
  EXPECT_EQ(text.back(), '\n');

  std::ostringstream quiet;
  StepProgress off(quiet, 10, /*enabled=*/false, false, nullptr);
  off.Begin(0, 0);
  off.Update(10, 1, 1);
  off.Finish();
  EXPECT_EQ(quiet.str(), "");
}

TEST(StepProgressTest, FactorsBelowOneKeepTwoSignificantDigits) {
  EXPECT_EQ(RealTimeFactorText(0.068), "0.068");
  EXPECT_EQ(RealTimeFactorText(0.0068), "0.0068");
  EXPECT_EQ(RealTimeFactorText(0.68), "0.68");
  EXPECT_EQ(RealTimeFactorText(0.994), "0.99");
  EXPECT_EQ(RealTimeFactorText(0.999), "1.0");
  EXPECT_EQ(RealTimeFactorText(12.345), "12.3");
  EXPECT_EQ(RealTimeFactorText(0), "0.0");
}

}  // namespace
}  // namespace swarmsim
