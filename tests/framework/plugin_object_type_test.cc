// A plugin's object type (framework/plugin_object_type.cc): the keys a
// plugin declares through add_object_type become a type like the built-in
// ones: documented defaults and ranges, values read and range-checked from
// a model file, scaled by their length power, copied and hashed.
#include "framework/plugin_object_type.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fake_reader.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;
using testing::FakeReader;

// The example plugin's beacon: a radius (a length) and a strength.
std::shared_ptr<const ObjectTypeDescriptor> Beacon() {
  const std::vector<SwarmsimObjectKey> keys = {
      {"radius", 0.5, 0.01, 100, 1, "m, how near counts"},
      {"strength", 1, 0, 10, 0, "how strongly it attracts"},
  };
  return MakePluginObjectType("beacon", "a marker robots are near or not", keys);
}

TEST(PluginObjectTypeTest, KeysAreDocumentedWithTheirDefaults) {
  const auto beacon = Beacon();
  EXPECT_STREQ(beacon->name, "beacon");
  EXPECT_STREQ(beacon->description, "a marker robots are near or not");
  ASSERT_EQ(beacon->keys.size(), 2u);
  EXPECT_STREQ(beacon->keys[0].name, "radius");
  EXPECT_STREQ(beacon->keys[0].default_text, "0.5");
  EXPECT_STREQ(beacon->keys[0].doc, "m, how near counts");
  EXPECT_STREQ(beacon->keys[1].default_text, "1");
}

TEST(PluginObjectTypeTest, AKeyNeedsANameAndADefaultInsideItsRange) {
  EXPECT_EQ(ErrorOf([] {
              MakePluginObjectType("t", "", {{"", 0, 0, 1, 0, ""}});
            }),
            "object type 't': a key needs a name");
  EXPECT_EQ(ErrorOf([] {
              MakePluginObjectType("t", "", {{"gain", 5, 0, 1, 0, ""}});
            }),
            "object type 't': the default of 'gain' is outside its range");
}

TEST(PluginObjectTypeTest, ValuesAreReadCheckedScaledCopiedAndHashed) {
  const auto beacon = Beacon();
  Scene scene;
  const ObjectType type = scene.RegisterType(*beacon);
  const ObjectId root = scene.AddDummy("bot", {}, {});
  const ObjectId b = scene.AddObject(type, "beacon", root, {}, nullptr);
  // Keys not given keep their defaults.
  beacon->read(*beacon, FakeReader{{"strength", 2.5}}, scene.row_data(b));
  const std::vector<double>* values = PluginObjectValues(scene, b);
  ASSERT_NE(values, nullptr);
  EXPECT_EQ(*values, (std::vector<double>{0.5, 2.5}));
  // A value outside the range names it (a failed read fails the whole load:
  // the row it was reading is not used).
  const ObjectId rejected = scene.AddObject(type, "rejected", {}, {}, nullptr);
  EXPECT_EQ(ErrorOf([&] {
              beacon->read(*beacon, FakeReader{{"radius", 200.0}}, scene.row_data(rejected));
            }),
            "model.yaml:2:3: 'radius' must be a number from 0.01 to 100");
  // Scaling: the radius is a length (power 1), the strength is not.
  scene.ScaleSubtree(root, 3);
  EXPECT_EQ(*PluginObjectValues(scene, b), (std::vector<double>{1.5, 2.5}));
  // A copy has the same values; the state hash sees them.
  const ObjectId copy = scene.DuplicateSubtree(root, {});
  EXPECT_EQ(*PluginObjectValues(scene, scene.FindObject("./beacon", copy)),
            (std::vector<double>{1.5, 2.5}));
  const auto hash = [&] {
    StateHasher h;
    beacon->hash_rows(scene, type, &h);
    return h.Digest();
  };
  const uint64_t before = hash();
  beacon->read(*beacon, FakeReader{{"strength", 3.0}}, scene.row_data(b));
  EXPECT_NE(hash(), before);
  // Not a plugin type's object: no values.
  EXPECT_EQ(PluginObjectValues(scene, root), nullptr);
  scene.RemoveSubtree(copy);
  EXPECT_EQ(PluginObjectValues(scene, copy), nullptr);
}

}  // namespace
}  // namespace swarmsim
