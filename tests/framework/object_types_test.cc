// The object-type table (framework/object_type.h): every built-in type is
// there once, with its hooks, and worlds/README.md documents every world-file
// key a type declares, so the docs cannot drift from the loader.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"

namespace swarmsim {
namespace {

std::string ReadmeText() {
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/README.md");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ObjectTypesTest, EveryBuiltInTypeIsListedOnceInObjectTypeOrder) {
  const auto types = CoreObjectTypes();
  ASSERT_EQ(types.size(), static_cast<size_t>(kBuiltinObjectTypes));
  std::set<std::string> names;
  for (size_t t = 0; t < types.size(); ++t) {
    EXPECT_TRUE(names.insert(types[t]->name).second) << types[t]->name;
    EXPECT_STREQ(ToString(static_cast<ObjectType>(t)), types[t]->name);
  }
  Scene scene;
  ObjectType found;
  ASSERT_TRUE(scene.FindType("joint", &found));
  EXPECT_EQ(found, ObjectType::kJoint);
  EXPECT_FALSE(scene.FindType("camera", &found));
}

TEST(ObjectTypesTest, WorldsReadmeDocumentsEveryKeyOfEveryType) {
  const std::string readme = ReadmeText();
  ASSERT_FALSE(readme.empty());
  // The `type` row of the object keys names every type.
  const size_t type_row = readme.find("| `type` | required |");
  ASSERT_NE(type_row, std::string::npos);
  const std::string row = readme.substr(type_row, readme.find('\n', type_row) - type_row);
  for (const ObjectTypeDescriptor* type : CoreObjectTypes())
    EXPECT_NE(row.find(std::string("`") + type->name + "`"), std::string::npos) << type->name;
  // Each type with keys has a "#### name" section whose table lists them.
  for (const ObjectTypeDescriptor* type : CoreObjectTypes()) {
    if (type->keys.empty()) continue;
    const size_t section = readme.find(std::string("\n#### ") + type->name + "\n");
    ASSERT_NE(section, std::string::npos) << "no '#### " << type->name << "' in worlds/README.md";
    const size_t next = readme.find("\n#### ", section + 1);
    const std::string text = readme.substr(section, next - section);
    for (const ObjectKey& key : type->keys) {
      EXPECT_NE(text.find(std::string("| `") + key.name + "` |"), std::string::npos)
          << type->name << "." << key.name << " is not documented in worlds/README.md";
      EXPECT_NE(key.doc, nullptr);
      EXPECT_NE(key.default_text, nullptr);
    }
  }
}

// Copying, scaling and removing go through each type's hooks: a scaled
// joint's limits scale with it, and removing swaps the last row into the
// hole (a force sensor's copy: tests/modules/force_sensor/force_sensor_type_test.cc).
TEST(ObjectTypesTest, CopyScaleAndRemoveUseEachTypesRules) {
  Scene scene;
  const ObjectId root = scene.AddDummy("bot", {}, {});
  JointData slide;
  slide.settings.Edit().type = JointType::kPrismatic;
  slide.settings.Edit().max_position = 0.5;
  const ObjectId joint = scene.AddJoint("slide", root, {}, slide);
  const ObjectId copy = scene.DuplicateSubtree(root, {});
  scene.ScaleSubtree(copy, 2);
  EXPECT_EQ(scene.joint(scene.FindObject("./slide", copy)).settings->max_position, 1.0);
  EXPECT_EQ(scene.joint(joint).settings->max_position, 0.5);
  scene.RemoveSubtree(root);
  ASSERT_EQ(scene.joints().size(), 1u);
  EXPECT_EQ(scene.joints()[0].settings->max_position, 1.0);
  EXPECT_EQ(scene.joint_owners()[0], scene.FindObject("./slide", copy).index());
}

}  // namespace
}  // namespace swarmsim
