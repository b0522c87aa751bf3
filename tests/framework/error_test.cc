// The text of swarmsim::Error and of internal errors (framework/error.cc):
// whatever a script or a world file throws stays a readable size, and a
// broken invariant says where and that it is a bug.
#include "framework/error.h"

#include <gtest/gtest.h>

#include <string>

#include "framework/utf8.h"
#include "tests/framework/error_of.h"

namespace swarmsim {
namespace {

TEST(CutErrorTextTest, CutsTheMiddleBetweenCharacters) {
  EXPECT_EQ(CutErrorText("short"), "short");
  const std::string long_text = "file.lua:3: " + std::string(10000, 'e') + " [in x]";
  const std::string cut = CutErrorText(long_text);
  EXPECT_LE(cut.size(), kMaxErrorTextBytes);
  EXPECT_EQ(cut.rfind("file.lua:3: eee", 0), 0u);
  EXPECT_CONTAINS(cut, " bytes cut) ... ");
  EXPECT_EQ(cut.substr(cut.size() - 8), "e [in x]");
  // Two-, three- and four-byte characters are never split.
  for (const std::string character : {"\xC3\xA9", "\xE2\x82\xAC", "\xF0\x9F\x98\x80"}) {
    for (size_t shift = 0; shift < 4; ++shift) {
      std::string text(shift, 'a');
      for (int i = 0; i < 5000; ++i) text += character;
      const std::string c = CutErrorText(text);
      EXPECT_LE(c.size(), kMaxErrorTextBytes);
      EXPECT_TRUE(IsValidUtf8(c)) << shift;
    }
  }
  // Every swarmsim::Error is cut so.
  EXPECT_LE(std::string(Error(std::string(1 << 20, 'x')).what()).size(), kMaxErrorTextBytes);
}

// The note counts exactly the bytes left out, so the start, the note's
// count and the end give back the original length.
TEST(CutErrorTextTest, TheNoteCountsTheBytesLeftOut) {
  const std::string text = std::string(3000, 'a') + std::string(3000, 'b');
  const std::string cut = CutErrorText(text, 1000);
  EXPECT_LE(cut.size(), 1000u);
  const size_t open = cut.find(" ... (");
  const size_t close = cut.find(" bytes cut) ... ");
  ASSERT_NE(open, std::string::npos);
  ASSERT_NE(close, std::string::npos);
  const size_t counted = std::stoul(cut.substr(open + 6, close - open - 6));
  const size_t kept = open + (cut.size() - close - std::string(" bytes cut) ... ").size());
  EXPECT_EQ(kept + counted, text.size());
  // Three quarters of what is kept is the start, where file:line is.
  EXPECT_GT(open, 2 * (cut.size() - close - 16));
  EXPECT_EQ(cut.front(), 'a');
  EXPECT_EQ(cut.back(), 'b');
  // Text at the limit is left alone; one byte more is cut.
  EXPECT_EQ(CutErrorText(std::string(1000, 'x'), 1000), std::string(1000, 'x'));
  EXPECT_NE(CutErrorText(std::string(1001, 'x'), 1000), std::string(1001, 'x'));
}

// A limit too small for the note itself still keeps some text on each side.
TEST(CutErrorTextTest, ATinyLimitStillKeepsBothEnds) {
  const std::string text = "start" + std::string(500, '-') + "end";
  const std::string cut = CutErrorText(text, 4);
  EXPECT_LT(cut.size(), text.size());
  EXPECT_EQ(cut.rfind("start", 0), 0u);
  EXPECT_EQ(cut.back(), 'd');
  EXPECT_CONTAINS(cut, "bytes cut");
}

TEST(ErrorTest, ShortMessagesAreKeptWhole) {
  EXPECT_STREQ(Error("world.yaml:3:5: unknown key 'robts'").what(),
               "world.yaml:3:5: unknown key 'robts'");
  const std::string at_limit(kMaxErrorTextBytes, 'z');
  EXPECT_EQ(Error(at_limit).what(), at_limit);
}

TEST(ErrorTest, AFailedCheckNamesTheConditionTheFileAndLineAndAsksForAReport) {
  int line = 0;
  std::string message;
  try {
    line = __LINE__ + 1;
    SWARMSIM_CHECK(1 + 1 == 3, "arithmetic");
  } catch (const InternalError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, std::string("internal error at ") + __FILE__ + ":" + std::to_string(line) +
                         ": check '1 + 1 == 3' failed: arithmetic "
                         "(this is a swarmsim bug; please report it)");
  // A check that holds does nothing; one without a message says no more.
  EXPECT_NO_THROW(SWARMSIM_CHECK(true, "never"));
  try {
    SWARMSIM_CHECK(false, "");
    ADD_FAILURE();
  } catch (const InternalError& e) {
    EXPECT_CONTAINS(e.what(), "check 'false' failed (this is a swarmsim bug");
  }
  // An internal error is not a user's mistake: catching Error misses it.
  EXPECT_THROW(
      {
        try {
          SWARMSIM_CHECK(false, "x");
        } catch (const Error&) {
        }
      },
      InternalError);
}

}  // namespace
}  // namespace swarmsim
