#include "framework/utf8.h"

#include <gtest/gtest.h>

namespace swarmsim {
namespace {

const std::string kFffd = "\xEF\xBF\xBD";

TEST(Utf8Test, ValidTextIsUnchanged) {
  for (const std::string text : {"", "plain ascii", "caf\xC3\xA9", "\xE2\x82\xAC 5",
                                 "\xF0\x9F\x90\x9D bee", "\xF4\x8F\xBF\xBF"}) {
    EXPECT_TRUE(IsValidUtf8(text)) << text;
    EXPECT_EQ(ValidUtf8(text), text);
  }
}

TEST(Utf8Test, EachMaximalInvalidSubpartBecomesOneReplacementCharacter) {
  EXPECT_EQ(ValidUtf8("a\xFF"
                      "b"),
            "a" + kFffd + "b");
  EXPECT_EQ(ValidUtf8("\xE2\x82"), kFffd);  // truncated at the end
  EXPECT_EQ(ValidUtf8("\xE2\x82"
                      "A"),
            kFffd + "A");                                       // truncated in the middle
  EXPECT_EQ(ValidUtf8("\xC0\xAF"), kFffd + kFffd);              // overlong '/'
  EXPECT_EQ(ValidUtf8("\xED\xA0\x80"), kFffd + kFffd + kFffd);  // a surrogate
  EXPECT_EQ(ValidUtf8("\xF4\x90\x80\x80"), kFffd + kFffd + kFffd + kFffd);  // past U+10FFFF
  EXPECT_EQ(ValidUtf8("\x80\x80"), kFffd + kFffd);  // lone continuation bytes
  EXPECT_FALSE(IsValidUtf8("ok\xFE"));
  EXPECT_TRUE(IsValidUtf8(ValidUtf8("\xC3(\xA0\xA1\xF0\x28\x8C\x28")));
}

}  // namespace
}  // namespace swarmsim
