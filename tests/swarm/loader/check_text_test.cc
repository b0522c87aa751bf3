// Tokens and numbers as the loader's mesh and URDF checks read them
// (swarm/loader/check_text.cc): integers and finite numbers as the formats
// write them, and messages that show a token safely and name file and line.
#include "swarm/loader/check_text.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/loader/mesh.h"

namespace swarmsim::loader {
namespace {

TEST(CheckTextTest, TokensAreSplitAtAnyWhitespace) {
  std::vector<std::string> tokens;
  ForEachToken(" \t1 two\r\n3.5\f\vfour  ", [&](std::string_view t) {
    tokens.emplace_back(t);
    return true;
  });
  EXPECT_EQ(tokens, (std::vector<std::string>{"1", "two", "3.5", "four"}));
  // Until the callback says stop.
  tokens.clear();
  ForEachToken("a b c", [&](std::string_view t) {
    tokens.emplace_back(t);
    return tokens.size() < 2;
  });
  EXPECT_EQ(tokens, (std::vector<std::string>{"a", "b"}));
}

TEST(CheckTextTest, UnsignedIsDigitsOnlyUpToTheMaximum) {
  uint64_t v = 7;
  EXPECT_TRUE(ParseUnsigned("0", 10, &v));
  EXPECT_EQ(v, 0u);
  EXPECT_TRUE(ParseUnsigned("0010", 10, &v));
  EXPECT_EQ(v, 10u);
  EXPECT_TRUE(ParseUnsigned("9999999999999999999", std::numeric_limits<uint64_t>::max(), &v));
  EXPECT_EQ(v, 9999999999999999999u);
  v = 7;
  for (const char* t : {"11", "", "-1", "+1", "1.0", "1e2", " 1", "0x1", "99999999999999999999"})
    EXPECT_FALSE(ParseUnsigned(t, 10, &v)) << t;
  EXPECT_EQ(v, 7u) << "a refused token leaves the value alone";
}

TEST(CheckTextTest, FiniteIsADecimalNumberAndNothingElse) {
  const auto read = [](std::string_view t) {
    double v = -42;
    return ParseFinite(t, &v) ? v : -42;
  };
  EXPECT_EQ(read("1"), 1);
  EXPECT_EQ(read("-0.5"), -0.5);
  EXPECT_EQ(read("+2.5e-3"), 2.5e-3);
  EXPECT_EQ(read(".5"), 0.5);
  EXPECT_EQ(read("5."), 5);
  EXPECT_EQ(read("1E3"), 1000);
  EXPECT_EQ(read("1e-400"), 0) << "too small reads as about 0";
  for (const char* t : {"", "+", "inf", "-inf", "nan", "NaN", "1e", "1e+", "1e400", "-1e400",
                        "0x10", " 1", "1 ", "1,5", "1.5.2", "--1", "e5"}) {
    double v = -42;
    EXPECT_FALSE(ParseFinite(t, &v)) << t;
    EXPECT_EQ(v, -42) << t;
  }
}

TEST(CheckTextTest, MessagesShowTokensShortAndPrintable) {
  EXPECT_EQ(Shown("abc"), "abc");
  EXPECT_EQ(Shown("a\tb\x01\x7f\xc3\xa9"), "a?b????");
  const std::string forty(40, 'x');
  EXPECT_EQ(Shown(forty), forty);
  EXPECT_EQ(Shown(forty + "y"), forty + "...");
  EXPECT_EQ(Quoted("a\nb"), "'a?b'");
  EXPECT_EQ(Count(0), "0");
  EXPECT_EQ(Count(999), "999");
  EXPECT_EQ(Count(1000), "1,000");
  EXPECT_EQ(Count(2000000), "2,000,000");
  EXPECT_EQ(Count(-1234567), "-1,234,567");
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(CheckTextTest, FailuresNameTheFileAndLine) {
  EXPECT_EQ(ErrorOf([] { Fail("part.obj", 12, "bad face"); }), "part.obj:12: bad face");
  EXPECT_EQ(ErrorOf([] { Fail("part.stl", 0, "too short"); }), "part.stl: too short");
  EXPECT_EQ(ErrorOf([] { CheckTriangleCount("a.obj", 3, kMaxMeshTriangles, "faces"); }), "");
  EXPECT_EQ(ErrorOf([] { CheckTriangleCount("a.obj", 3, kMaxMeshTriangles + 1, "has"); }),
            "a.obj:3: has more than 2,000,000 triangles, the limit for a mesh file (simplify it, "
            "or split it into parts)");
}

// Tags that nest pass, whatever comments, CDATA, processing instructions,
// a DOCTYPE and quoted '>' hold; the first tag that breaks the nesting is
// named with its line.
TEST(CheckTextTest, XmlNestingNamesTheTagThatBreaksIt) {
  int line = -1;
  EXPECT_EQ(XmlNestingProblem("<?xml version=\"1.0\"?>\n<!DOCTYPE r>\n<r a='x>y' b=\"</r>\">\n"
                              "<!-- </q> --><![CDATA[ </q> <x> ]]><e/>\n<f>t</f></r>\n",
                              &line),
            "");
  EXPECT_EQ(line, 0);
  EXPECT_EQ(XmlNestingProblem("<r>\n<a>\n</b>\n</r>\n", &line),
            "</b> does not close <a> (line 2): is it misspelt?");
  EXPECT_EQ(line, 3);
  EXPECT_EQ(
      XmlNestingProblem("<r>\n<a>\n</r>\n", &line),
      "</r> comes before <a> (line 2) is closed: it needs its </a> first (or to end with />)");
  EXPECT_EQ(line, 3);
  EXPECT_EQ(XmlNestingProblem("<r/>\n</r>\n", &line), "</r> closes no open element");
  EXPECT_EQ(line, 2);
  EXPECT_EQ(XmlNestingProblem("<r>\n<a>\n", &line),
            "<a> (line 2) is never closed (the file ends first)");
  EXPECT_EQ(line, 2);
  EXPECT_EQ(XmlNestingProblem("<r>\n<a n='x/>\n</r>\n", &line),
            "an attribute value of <a> (line 2) has no closing ' (a quote missing?)");
  EXPECT_EQ(line, 2);
}

}  // namespace
}  // namespace swarmsim::loader
