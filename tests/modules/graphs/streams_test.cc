// The text form of a graph's streams (modules/graphs/streams.cc):
// "[NAME =] KIND [PATH] [COMPONENT]" parsed into streams (a vector without
// a component gives three), and every mistake a clear error.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "modules/graphs/rows.h"
#include "tests/framework/error_of.h"

namespace swarmsim::graphs {
namespace {

using testing::ErrorOf;

std::vector<StreamSpec> Parse(std::string_view text) {
  std::vector<StreamSpec> out;
  ParseStream(text, &out);
  return out;
}

std::string ParseError(std::string_view text) {
  return ErrorOf([&] { Parse(text); });
}

TEST(GraphStreamsTest, AComponentGivesOneStreamNamedAfterIt) {
  const auto s = Parse("position :/body z");
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].name, "position :/body z");
  EXPECT_EQ(s[0].kind, StreamKind::kPosition);
  EXPECT_EQ(s[0].component, Component::kZ);
  EXPECT_EQ(s[0].path, ":/body");
  EXPECT_EQ(s[0].unit, "m");
  const auto named = Parse("  height =   position   ./body   norm ");
  ASSERT_EQ(named.size(), 1u);
  EXPECT_EQ(named[0].name, "height");
  EXPECT_EQ(named[0].component, Component::kNorm);
  EXPECT_EQ(named[0].path, "./body");
}

TEST(GraphStreamsTest, AVectorWithoutAComponentGivesThreeStreams) {
  const auto xyz = Parse("velocity /bot");
  ASSERT_EQ(xyz.size(), 3u);
  EXPECT_EQ(xyz[0].name, "velocity /bot x");
  EXPECT_EQ(xyz[1].component, Component::kY);
  EXPECT_EQ(xyz[2].name, "velocity /bot z");
  EXPECT_EQ(xyz[2].unit, "m/s");
  const auto angles = Parse("attitude = orientation /bot");
  ASSERT_EQ(angles.size(), 3u);
  EXPECT_EQ(angles[0].name, "attitude.roll");
  EXPECT_EQ(angles[1].component, Component::kPitch);
  EXPECT_EQ(angles[2].name, "attitude.yaw");
  EXPECT_EQ(angles[2].unit, "rad");
}

TEST(GraphStreamsTest, ScalarsAndScriptStreams) {
  const auto joint = Parse("joint :/hip");
  ASSERT_EQ(joint.size(), 1u);
  EXPECT_EQ(joint[0].kind, StreamKind::kJoint);
  EXPECT_EQ(joint[0].component, Component::kNone);
  EXPECT_EQ(joint[0].unit, "rad or m");
  const auto a = Parse("script speed");
  const auto b = Parse("speed = script");
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(a[0].name, "speed");
  EXPECT_EQ(b[0].name, "speed");
  EXPECT_EQ(a[0].kind, StreamKind::kScript);
  EXPECT_EQ(a[0].path, "");
  // Each kind a user may write.
  for (const char* text : {"angular_velocity /b z", "joint_velocity /j", "proximity /p",
                           "force /f x", "torque /f norm", "distance /d"})
    EXPECT_EQ(ParseError(text), "") << text;
}

TEST(GraphStreamsTest, MistakesAreErrorsQuotingTheStream) {
  EXPECT_CONTAINS(ParseError("positon :/body z"),
                  "stream 'positon :/body z': unknown stream kind 'positon'");
  EXPECT_CONTAINS(ParseError("positon :/body z"), "did you mean 'position'");
  EXPECT_CONTAINS(ParseError("positon :/body z"), "(kinds: position, orientation,");
  EXPECT_CONTAINS(ParseError(""), "expected '[NAME =] KIND [PATH] [COMPONENT]'");
  EXPECT_CONTAINS(ParseError("position body z"),
                  "'position' needs an object path starting with '/', './' or ':'");
  EXPECT_CONTAINS(ParseError("position /body w"),
                  "'position' has no component 'w' (components: x, y, z, norm; none: all three)");
  EXPECT_CONTAINS(ParseError("orientation /body x"),
                  "(components: roll, pitch, yaw; none: all three)");
  EXPECT_CONTAINS(ParseError("joint /hip x"), "'joint' is one number and takes no component 'x'");
  EXPECT_CONTAINS(ParseError("position /body z extra"), "too many words after the path '/body'");
  EXPECT_CONTAINS(ParseError("a b = position /body z"),
                  "a stream's name is one word before one '='");
  EXPECT_CONTAINS(ParseError("a = b = script"), "a stream's name is one word before one '='");
  EXPECT_CONTAINS(ParseError("a,b = position /body z"), "a stream's name may not hold ','");
  EXPECT_CONTAINS(ParseError("script"), "a script stream needs a name");
  EXPECT_CONTAINS(ParseError("speed = script speed"), "a script stream takes its name once");
  EXPECT_CONTAINS(ParseError("script a b"), "a script stream takes its name once");
}

}  // namespace
}  // namespace swarmsim::graphs
