// The XML pass of a URDF import (swarm/loader/urdf_xml.h): the lines the
// import's messages name, each visual's colour as urdfdom resolves it, the
// elements it ignores, and the structural mistakes urdfdom lets through,
// each an error naming the file and the line.
#include "swarm/loader/urdf_xml.h"

#include <gtest/gtest.h>

#include <string>

#include "framework/error.h"
#include "tests/framework/error_of.h"

namespace swarmsim::loader {
namespace {

constexpr const char* kHead = "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n";  // lines 1-2

std::string ErrorOfXml(const std::string& body) {
  return testing::ErrorOf([&] { ReadUrdfXml(std::string(kHead) + body, "r.urdf"); });
}

TEST(UrdfXmlTest, RecordsTheLinesMessagesName) {
  const UrdfXmlFacts f =
      ReadUrdfXml(std::string(kHead) +
                      "  <link name=\"base\">\n"                                              // 3
                      "    <visual><geometry><box size=\"1 1 1\"/></geometry></visual>\n"     // 4
                      "    <collision>\n      <geometry><sphere radius=\"1\"/></geometry>\n"  // 5,
                                                                                              // 6
                      "    </collision>\n"                                                    // 7
                      "    <inertial><mass value=\"1\"/>\n"                                   // 8
                      "      <inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" "
                      "iyz=\"0\"/>\n"                                 // 9
                      "    </inertial>\n  </link>\n"                  // 10, 11
                      "  <link name=\"a\"/>\n  <link name=\"b\"/>\n"  // 12, 13
                      "  <joint name=\"jb\" type=\"continuous\"><parent link=\"a\"/><child "
                      "link=\"b\"/>\n"                           // 14
                      "    <mimic joint=\"ja\"/>\n  </joint>\n"  // 15, 16
                      "  <joint name=\"ja\" type=\"continuous\"><parent link=\"base\"/><child "
                      "link=\"a\"/>"
                      "</joint>\n</robot>\n",  // 17
                  "r.urdf");
  EXPECT_EQ(f.link_line.at("base"), 3);
  EXPECT_EQ(f.link_line.at("b"), 13);
  EXPECT_EQ(f.joint_line.at("jb"), 14);
  EXPECT_EQ(f.joint_line.at("ja"), 17);
  EXPECT_EQ(f.mimic_line.at("jb"), 15);
  EXPECT_EQ(f.inertia_line.at("base"), 9);
  EXPECT_FALSE(f.inertia_line.contains("a"));
  // A visual's line is its geometry's shape; a collision's too (line 6, not 5).
  EXPECT_EQ(f.visual_lines.at("base"), std::vector<int>{4});
  EXPECT_EQ(f.collision_lines.at("base"), std::vector<int>{6});
  // Document order of joints, whatever their names.
  EXPECT_LT(f.joint_order.at("jb"), f.joint_order.at("ja"));
  EXPECT_TRUE(f.ignored.empty());
}

TEST(UrdfXmlTest, ColoursComeFromTheVisualsMaterialAsUrdfdomResolvesThem) {
  const std::string box = "<geometry><box size=\"1 1 1\"/></geometry>";
  const UrdfXmlFacts f = ReadUrdfXml(
      std::string(kHead) + "  <material name=\"blue\"><color rgba=\"0 0 1 1\"/></material>\n" +
          "  <link name=\"a\">\n"
          "    <visual>" +
          box +
          "<material name=\"own\"><color rgba=\"1 0.5 0 1\"/></material></visual>\n"
          "    <visual>" +
          box +
          "<material name=\"blue\"/></visual>\n"
          "    <visual>" +
          box +
          "<material name=\"own\"/></visual>\n"
          "    <visual>" +
          box +
          "</visual>\n"
          "    <visual>" +
          box +
          "<material name=\"clear\"><color rgba=\"1 1 1 0\"/></material></visual>\n"
          "    <visual>" +
          box +
          "<material name=\"nowhere\"/></visual>\n"
          "  </link>\n</robot>\n",
      "r.urdf");
  const auto& c = f.visual_colors.at("a");
  ASSERT_EQ(c.size(), 6u);
  ASSERT_TRUE(c[0]);  // inline
  EXPECT_EQ(c[0]->x, 1);
  EXPECT_EQ(c[0]->y, 0.5);
  EXPECT_EQ(c[0]->z, 0);
  ASSERT_TRUE(c[1]);  // the robot's named material
  EXPECT_EQ(c[1]->z, 1);
  ASSERT_TRUE(c[2]);  // a material another visual defined with a colour
  EXPECT_EQ(c[2]->y, 0.5);
  EXPECT_FALSE(c[3]);  // no material
  EXPECT_FALSE(c[4]);  // alpha 0: no colour
  EXPECT_FALSE(c[5]);  // a name defined nowhere
}

TEST(UrdfXmlTest, IgnoredElementsAreCountedWithTheirFirstLine) {
  const UrdfXmlFacts f = ReadUrdfXml(
      std::string(kHead) +
          "  <link name=\"a\"/>\n  <link name=\"b\"/>\n"  // 3, 4
          "  <gazebo reference=\"a\"/>\n"                 // 5
          "  <joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/>\n"  // 6
          "    <dynamics damping=\"0.1\" friction=\"0.2\"/>\n"                                 // 7
          "    <calibration rising=\"0\"/>\n  </joint>\n"           // 8, 9
          "  <transmission name=\"t\"/>\n  <gazebo/>\n</robot>\n",  // 10, 11
      "r.urdf");
  EXPECT_EQ(f.ignored.at("<gazebo>"), std::make_pair(2, 5));
  EXPECT_EQ(f.ignored.at("<transmission>"), std::make_pair(1, 10));
  EXPECT_EQ(f.ignored.at("<calibration> in a joint"), std::make_pair(1, 8));
  EXPECT_EQ(f.ignored.at("joint <dynamics> friction (not simulated)"), std::make_pair(1, 7));
}

// What the parser refuses that is not a nesting mistake is said in words,
// not as tinyxml2's error names ("XML_ERROR_PARSING_ATTRIBUTE ErrorID=7").
TEST(UrdfXmlTest, WhatTheXmlParserRefusesIsSaidInWords) {
  const std::string attribute = ErrorOfXml("  <link name=a/>\n</robot>\n");
  EXPECT_CONTAINS(attribute,
                  "r.urdf:3: malformed XML: an attribute of <link> is not name=\"value\" (its "
                  "quotes missing, or an attribute given twice)");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\" name=\"b\"/>\n</robot>\n"),
                  "r.urdf:3: malformed XML: an attribute of <link> is not name=\"value\"");
  const std::string comment = ErrorOfXml("  <link name=\"a\"/>\n  <!-- open\n</robot>\n");
  EXPECT_CONTAINS(comment,
                  "r.urdf:4: malformed XML: a comment <!-- is never closed with --> (the file "
                  "ends first)");
  for (const std::string& e : {attribute, comment})
    EXPECT_EQ(e.find("XML_"), std::string::npos) << e;
}

TEST(UrdfXmlTest, StructuralMistakesNameTheFileAndTheLine) {
  // Tags that do not nest: named at the tag that broke them.
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\">\n  <link name=\"b\"/>\n</robot>\n"),
                  "r.urdf:5: malformed XML: </robot> comes before <link> (line 3) is closed: it "
                  "needs its </link> first (or to end with />)");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n  <!-- </robot> -->\n</robt>\n"),
                  "r.urdf:5: malformed XML: </robt> does not close <robot> (line 2): is it "
                  "misspelt?");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n</robot>\n</robot>\n"),
                  "r.urdf:5: malformed XML: </robot> closes no open element");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n</robot>\n<extra/>\n"),
                  "r.urdf:5: <extra> after </robot>: a URDF file holds one <robot> element");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a/>\n  <link name=\"b\"/>\n</robot>\n"),
                  "r.urdf:3: malformed XML: an attribute value of <link> (line 3) has no "
                  "closing \" (a quote missing?)");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a>b\">\n  </link>\n"),
                  "r.urdf:2: malformed XML: <robot> (line 2) is never closed (the file ends "
                  "first)");
  EXPECT_CONTAINS(testing::ErrorOf([] { ReadUrdfXml("<model name=\"x\"/>", "r.urdf"); }),
                  "r.urdf:1: a URDF file's root element must be <robot>");
  EXPECT_CONTAINS(ErrorOfXml("</robot>\n"), "r.urdf:2: the robot has no <link>");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n  <link name=\"a\"/>\n</robot>\n"),
                  "r.urdf:4: link 'a' is defined twice (first at line 3)");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n  <joint name=\"j\" type=\"fixed\">\n"
                             "    <parent link=\"a\"/><child link=\"ghost\"/>\n  </joint>\n"
                             "</robot>\n"),
                  "r.urdf:4: joint 'j' names child link 'ghost', which the file does not define");
  EXPECT_CONTAINS(
      ErrorOfXml("  <link name=\"a\"/>\n  <link name=\"b\"/>\n"
                 "  <joint name=\"j1\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/>"
                 "</joint>\n"
                 "  <joint name=\"j2\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/>"
                 "</joint>\n</robot>\n"),
      "the kinematic tree has a loop");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n  <link name=\"b\"/>\n</robot>\n"),
                  "r.urdf:4: the robot has several root links ('a', 'b')");
  EXPECT_CONTAINS(
      ErrorOfXml("  <link name=\"a\"/>\n  <link name=\"b\"/>\n"
                 "  <joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>"
                 "<mimic joint=\"nobody\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
                 "velocity=\"1\"/></joint>\n</robot>\n"),
      "r.urdf:5: joint 'j': <mimic joint=\"nobody\"> names a joint the file does not define");
  // A mimic of a fixed joint (merged away: nothing to follow) or of itself is
  // named at its <mimic>, not as a path the started world cannot find.
  const std::string two_joints =
      "  <link name=\"a\"/>\n  <link name=\"b\"/>\n  <link name=\"c\"/>\n"
      "  <joint name=\"weld\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/>"
      "</joint>\n"
      "  <joint name=\"j\" type=\"revolute\"><parent link=\"b\"/><child link=\"c\"/>\n"
      "    <mimic joint=\"MASTER\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
      "velocity=\"1\"/></joint>\n</robot>\n";
  auto with_master = [&](const std::string& master) {
    std::string body = two_joints;
    body.replace(body.find("MASTER"), 6, master);
    return body;
  };
  EXPECT_CONTAINS(ErrorOfXml(with_master("weld")),
                  "r.urdf:8: joint 'j': <mimic joint=\"weld\">: 'weld' is a fixed joint, which "
                  "has no position to follow");
  EXPECT_CONTAINS(ErrorOfXml(with_master("j")),
                  "r.urdf:8: joint 'j': <mimic> names the joint itself");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n  <link name=\"b\"/>\n"
                             "  <joint name=\"j\" type=\"prismatic\"><parent link=\"a\"/>"
                             "<child link=\"b\"/></joint>\n</robot>\n"),
                  "r.urdf:5: joint 'j' is prismatic and needs <limit lower upper effort velocity>");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n  <link name=\"b\"/>\n"
                             "  <joint name=\"j\" type=\"revolutee\"><parent link=\"a\"/><child "
                             "link=\"b\"/></joint>\n</robot>\n"),
                  "r.urdf:5: joint 'j': unknown type 'revolutee'");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\">\n    <collision><geometry><cone/></geometry>"
                             "</collision>\n  </link>\n</robot>\n"),
                  "r.urdf:4: link 'a' <collision>: unknown geometry <cone>");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\">\n    <inertial>\n      <mass value=\"-2\"/>\n"
                             "    </inertial>\n  </link>\n</robot>\n"),
                  "r.urdf:5: link 'a': <mass value=\"-2\">");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n  <link name=\"b\"/>\n"
                             "  <joint name=\"j\" type=\"continuous\"><parent link=\"a\"/>"
                             "<child link=\"b\"/>\n    <dynamics damping=\"-1\"/>\n  </joint>\n"
                             "</robot>\n"),
                  "r.urdf:6: joint 'j': <dynamics damping=\"-1\"> must be a non-negative number");
  // Finite but absurd: an ODE assertion at the first step, naming no link.
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\">\n    <inertial>\n      <mass value=\"1e308\"/>\n"
                             "    </inertial>\n  </link>\n</robot>\n"),
                  "r.urdf:5: link 'a': <mass value=\"1e+308\"> must be a non-negative number of "
                  "kg, at most 1e9");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\">\n    <inertial>\n      <mass value=\"1\"/>\n"
                             "      <inertia ixx=\"1e300\" iyy=\"1\" izz=\"1\" ixy=\"0\" "
                             "ixz=\"0\" iyz=\"0\"/>\n    </inertial>\n  </link>\n</robot>\n"),
                  "r.urdf:6: link 'a': <inertia ixx=\"1e+300\"> is past 1e12 kg m^2");
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"/>\n  <link name=\"b\"/>\n"
                             "  <joint name=\"j\" type=\"continuous\"><parent link=\"a\"/>"
                             "<child link=\"b\"/>\n    <dynamics damping=\"1e300\"/>\n  </joint>\n"
                             "</robot>\n"),
                  "at most 1e12");
  // A number urdfdom would misread is refused here, with its line (urdf_numbers.h).
  EXPECT_CONTAINS(ErrorOfXml("  <link name=\"a\"><visual><geometry><box size=\"1 x 1\"/>"
                             "</geometry></visual></link>\n</robot>\n"),
                  "r.urdf:3:");
}

}  // namespace
}  // namespace swarmsim::loader
