// Numbers in a URDF file (issue 26): every attribute urdfdom reads a number
// from holds finite numbers, else the import fails naming the file, the line
// and the attribute; urdfdom's own message named no line, and an unreadable
// <mass value> made a massless link.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "swarm/loader/urdf.h"

namespace swarmsim::loader {
namespace {

namespace fs = std::filesystem;

class UrdfNumbersTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("swarmsim_urdf_numbers_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A two-link robot; `link` and `joint` are inserted into the base link
  // and the joint (line 3 holds the base link, line 4 the inserted part of
  // it; line 7 the joint, line 8 its inserted part).
  std::string Robot(const std::string& link, const std::string& joint,
                    const std::string& top = "") {
    return "<?xml version=\"1.0\"?>\n"
           "<robot name=\"r\">\n"
           "  <link name=\"base\">\n" +
           link +
           "\n"
           "  </link>\n"
           "  <link name=\"arm\"/>\n"
           "  <joint name=\"j\" type=\"revolute\">\n" +
           joint +
           "\n"
           "    <parent link=\"base\"/><child link=\"arm\"/>\n"
           "    <limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\n"
           "  </joint>\n" +
           top + "</robot>\n";
  }
  std::string ErrorOf(const std::string& text) {
    std::ofstream(dir_ / "r.urdf") << text;
    try {
      ImportUrdf(dir_ / "r.urdf", "", "r.urdf", {}, nullptr);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }
  // The error of `text`, from "r.urdf:" on.
  std::string Message(const std::string& text) {
    const std::string e = ErrorOf(text);
    const size_t at = e.find("r.urdf:");
    return at == std::string::npos ? e : e.substr(at);
  }

  fs::path dir_;
};

const std::string kInertial =
    "    <inertial><mass value=\"1\"/>"
    "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";

TEST_F(UrdfNumbersTest, ReadableNumbersLoad) {
  EXPECT_EQ(ErrorOf(Robot("    <inertial><origin xyz=\" +1 .5 2e-3 \" rpy=\"0 0 -1.5707963\"/>"
                          "<mass value=\"1.\"/><inertia ixx=\"1e-3\" iyy=\"1E-3\" izz=\"0.001\" "
                          "ixy=\"0\" ixz=\"-0\" iyz=\"0\"/></inertial>\n"
                          "    <visual><geometry><box size=\"0.1 0.2 0.3\"/></geometry>"
                          "<material name=\"m\"><color rgba=\"1 0 0 1\"/></material></visual>",
                          "    <axis xyz=\"0 0 1\"/><dynamics damping=\"0.1\" friction=\"0\"/>")),
            "no error");
}

// Lengths past what a world may use (1e6 m), sizes below 0, negative
// limits: refused as the world file refuses them, naming the element.
TEST_F(UrdfNumbersTest, NumbersOutsideTheirRangeAreErrors) {
  EXPECT_EQ(
      Message(Robot("    <visual><geometry><box size=\"1 1e10 1\"/></geometry></visual>", "")),
      "r.urdf:4: link 'base' <visual>: <box size=\"1 1e10 1\">: '1e10' is not a size from "
      "0 to 1e6 m");
  EXPECT_EQ(Message(Robot("", "    <origin xyz=\"1e12 0 0.1\"/>")),
            "r.urdf:8: joint 'j': <origin xyz=\"1e12 0 0.1\">: '1e12' is not a coordinate from "
            "-1e6 to 1e6 m");
  EXPECT_EQ(Message(Robot("    <collision><geometry><sphere radius=\"-0.1\"/></geometry>"
                          "</collision>",
                          "")),
            "r.urdf:4: link 'base' <collision>: <sphere radius=\"-0.1\">: '-0.1' is not a size "
            "from 0 to 1e6 m");
  std::string negative = Robot("", "");
  const std::string limit = "effort=\"1\" velocity=\"1\"";
  negative.replace(negative.find(limit), limit.size(), "effort=\"1\" velocity=\"-5\"");
  EXPECT_EQ(Message(negative),
            "r.urdf:10: joint 'j': <limit velocity=\"-5\">: '-5' is not 0 or more (m/s or "
            "rad/s)");
}

TEST_F(UrdfNumbersTest, UnreadableMassIsAnErrorNotAMasslessLink) {
  EXPECT_EQ(Message(Robot("    <inertial><mass value=\"abc\"/>"
                          "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
                          "</inertial>",
                          "")),
            "r.urdf:4: link 'base' <inertial>: <mass value=\"abc\">: 'abc' is not a finite number");
  EXPECT_EQ(Message(Robot("    <inertial><mass value=\"\"/>"
                          "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
                          "</inertial>",
                          "")),
            "r.urdf:4: link 'base' <inertial>: <mass value=\"\"> needs a number");
  EXPECT_EQ(
      Message(Robot("    <inertial><mass value=\"1\"/>"
                    "<inertia ixx=\"inf\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
                    "</inertial>",
                    "")),
      "r.urdf:4: link 'base' <inertial>: <inertia ixx=\"inf\">: 'inf' is not a finite number");
}

TEST_F(UrdfNumbersTest, VectorsHoldTheirCountOfFiniteNumbers) {
  EXPECT_EQ(Message(Robot(kInertial + "\n    <visual><origin xyz=\"0 nan 0\"/>"
                                      "<geometry><sphere radius=\"1\"/></geometry></visual>",
                          "")),
            "r.urdf:5: link 'base' <visual>: <origin xyz=\"0 nan 0\">: 'nan' is not a finite "
            "number");
  EXPECT_EQ(Message(Robot("", "    <origin xyz=\"0 0 0\" rpy=\"0 0\"/>")),
            "r.urdf:8: joint 'j': <origin rpy=\"0 0\"> needs 3 numbers (it has 2)");
  EXPECT_EQ(Message(Robot("", "    <axis xyz=\"0 0 1 0\"/>")),
            "r.urdf:8: joint 'j': <axis xyz=\"0 0 1 0\"> needs 3 numbers (it has 4)");
  EXPECT_EQ(Message(Robot("    <collision><geometry><box size=\"1 1 1e400\"/></geometry>"
                          "</collision>",
                          "")),
            "r.urdf:4: link 'base' <collision>: <box size=\"1 1 1e400\">: '1e400' is not a finite "
            "number");
  EXPECT_EQ(Message(Robot("", "", "  <material name=\"red\"><color rgba=\"1 0 0\"/></material>\n")),
            "r.urdf:12: material 'red': <color rgba=\"1 0 0\"> needs 4 numbers (it has 3)");
}

TEST_F(UrdfNumbersTest, JointNumbersNameTheJoint) {
  EXPECT_EQ(Message(Robot("", "    <dynamics damping=\"1,5\"/>")),
            "r.urdf:8: joint 'j': <dynamics damping=\"1,5\">: '1,5' is not a finite number");
  EXPECT_EQ(Message(Robot("", "    <mimic joint=\"j\" multiplier=\"0x2\"/>")),
            "r.urdf:8: joint 'j': <mimic multiplier=\"0x2\">: '0x2' is not a finite number");
  EXPECT_EQ(Message(Robot("", "    <safety_controller k_velocity=\"fast\"/>")),
            "r.urdf:8: joint 'j': <safety_controller k_velocity=\"fast\">: 'fast' is not a finite "
            "number");
}

// Every numeric attribute urdfdom 3 reads (its parsers, listed here from
// urdfdom's link.cpp, joint.cpp and pose.cpp, not from urdf_numbers.cc),
// holding a word: an error naming the line, the element and the attribute.
TEST_F(UrdfNumbersTest, EveryAttributeUrdfdomReadsIsCheckedWithItsLine) {
  struct Case {
    bool in_joint;        // in the joint (line 8), else in the base link (line 4)
    std::string snippet;  // "@" marks the attribute's value
    std::string element;  // "<origin xyz" as the message shows it
  };
  std::vector<Case> cases;
  const std::string inertia_keys[] = {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"};
  for (const std::string& key : inertia_keys) {
    std::string inertia = "<inertia";
    for (const std::string& k : inertia_keys)
      inertia += " " + k + "=\"" + (k == key ? "@" : "1") + "\"";
    cases.push_back(
        {false, "<inertial><mass value=\"1\"/>" + inertia + "/></inertial>", "<inertia " + key});
  }
  cases.push_back({false, "<inertial><mass value=\"@\"/></inertial>", "<mass value"});
  for (const char* key : {"xyz", "rpy"})
    cases.push_back({false,
                     std::string("<inertial><origin ") + key +
                         "=\"@\"/><mass value=\"1\"/>"
                         "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
                         "</inertial>",
                     std::string("<origin ") + key});
  for (const char* part : {"visual", "collision"}) {
    const std::string open = std::string("<") + part + ">", close = std::string("</") + part + ">";
    for (const char* key : {"xyz", "rpy"})
      cases.push_back({false,
                       open + "<origin " + key +
                           "=\"@\"/><geometry><sphere radius=\"1\"/>"
                           "</geometry>" +
                           close,
                       std::string("<origin ") + key});
    for (const auto& [geometry, element] :
         {std::pair<std::string, std::string>{"<box size=\"@\"/>", "<box size"},
          {"<cylinder radius=\"@\" length=\"1\"/>", "<cylinder radius"},
          {"<cylinder radius=\"1\" length=\"@\"/>", "<cylinder length"},
          {"<sphere radius=\"@\"/>", "<sphere radius"},
          {"<mesh filename=\"m.stl\" scale=\"@\"/>", "<mesh scale"}})
      cases.push_back({false, open + "<geometry>" + geometry + "</geometry>" + close, element});
  }
  cases.push_back({false,
                   "<visual><geometry><sphere radius=\"1\"/></geometry><material name=\"m\">"
                   "<color rgba=\"@\"/></material></visual>",
                   "<color rgba"});
  cases.push_back({true, "<origin xyz=\"@\"/>", "<origin xyz"});
  cases.push_back({true, "<origin rpy=\"@\"/>", "<origin rpy"});
  cases.push_back({true, "<axis xyz=\"@\"/>", "<axis xyz"});
  for (const char* key : {"lower", "upper", "effort", "velocity"}) {
    std::string limit = "<limit";
    for (const char* k : {"lower", "upper", "effort", "velocity"})
      limit += std::string(" ") + k + "=\"" + (std::string(k) == key ? "@" : "1") + "\"";
    cases.push_back({true, limit + "/>", std::string("<limit ") + key});
  }
  for (const char* key : {"damping", "friction"})
    cases.push_back(
        {true, std::string("<dynamics ") + key + "=\"@\"/>", std::string("<dynamics ") + key});
  for (const char* key : {"multiplier", "offset"})
    cases.push_back({true, std::string("<mimic joint=\"j\" ") + key + "=\"@\"/>",
                     std::string("<mimic ") + key});
  for (const char* key : {"soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"})
    cases.push_back({true, std::string("<safety_controller ") + key + "=\"@\"/>",
                     std::string("<safety_controller ") + key});
  for (const char* key : {"rising", "falling"})
    cases.push_back({true, std::string("<calibration ") + key + "=\"@\"/>",
                     std::string("<calibration ") + key});
  for (const Case& c : cases) {
    std::string snippet = "    " + c.snippet;
    snippet.replace(snippet.find('@'), 1, "abc");
    const std::string e = Message(c.in_joint ? Robot("", snippet) : Robot(snippet, ""));
    EXPECT_EQ(e.substr(0, 9), c.in_joint ? "r.urdf:8:" : "r.urdf:4:") << c.snippet << ": " << e;
    EXPECT_NE(e.find(c.element + "=\"abc\">: 'abc' is not a finite number"), std::string::npos)
        << c.snippet << ": " << e;
  }
  // The robot's own materials.
  EXPECT_EQ(Message(Robot("", "", "  <material name=\"m\"><color rgba=\"abc\"/></material>\n")),
            "r.urdf:12: material 'm': <color rgba=\"abc\">: 'abc' is not a finite number");
}

// What tinyxml2 (and urdfdom behind it) would misread is refused with its
// line: a DOCTYPE's declarations are never applied, and an entity other
// than XML's own is kept as its literal text ('&len;' as a link's name).
TEST_F(UrdfNumbersTest, DtdDeclarationsAndUnknownEntitiesNameTheirLine) {
  const auto with_doctype = [&](const std::string& doctype, const std::string& link) {
    std::string text = Robot(link, "");
    text.insert(text.find('\n') + 1, doctype);
    return text;
  };
  EXPECT_EQ(Message(with_doctype("<!DOCTYPE robot [\n  <!ENTITY len \"0.5\">\n]>\n",
                                 "    <visual><geometry><box size=\"&len; 1 1\"/></geometry>"
                                 "</visual>")),
            "r.urdf:2: a <!DOCTYPE> with declarations ([...]): the URDF reader applies no DTD, so "
            "its entities and defaults would be lost; write the values out and remove them");
  EXPECT_EQ(Message(Robot("", "", "  <link name=\"&tool;\"/>\n")),
            "r.urdf:12: '&tool;' refers to an entity the URDF reader does not know (it knows "
            "XML's own: &lt; &gt; &amp; &quot; &apos; and &#...;); write the value out");
  // A '&' that starts no reference: urdfdom's TinyXML dropped it where
  // tinyxml2 kept it, so a joint 'l&eft' had two names and the import
  // ended in an uncaught std::out_of_range (found by the urdf fuzzer).
  EXPECT_EQ(Message(Robot("", "", "  <link name=\"l&eft\"/>\n")),
            "r.urdf:12: a '&' that starts no reference ('&eft\"'): XML writes a '&' as &amp;");
  EXPECT_EQ(Message(Robot("", "", "  <link name=\"a & b\"/>\n")),
            "r.urdf:12: a '&' that starts no reference ('& '): XML writes a '&' as &amp;");
  // A DOCTYPE that declares nothing, XML's own entities and character
  // references, and anything in a comment or CDATA load.
  EXPECT_EQ(ErrorOf(with_doctype("<!DOCTYPE robot SYSTEM \"urdf.dtd\">\n",
                                 "    <!-- &len; --><visual name=\"a&amp;b&#67;&#x44;&lt;\">"
                                 "<geometry><box size=\"1 1 1\"/></geometry></visual>")),
            "no error");
}

}  // namespace
}  // namespace swarmsim::loader
