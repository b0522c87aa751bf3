// The paint_nozzle type's hooks (paint_nozzle_type.cc) through a Scene: the
// radius scales with the model, a copy keeps colour and state.
#include <gtest/gtest.h>

#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "modules/builtin.h"
#include "modules/paint/paint_nozzle.h"

namespace swarmsim {
namespace {

// A scene with the built-in registry's types, as every World's has.
struct Fixture {
  ModuleRegistry registry;
  Scene scene;
  ObjectType nozzle{};
  Fixture() {
    RegisterBuiltinModules(&registry);
    for (const ObjectTypeDescriptor* type : registry.object_types()) scene.RegisterType(*type);
    EXPECT_TRUE(scene.FindType(kPaintNozzleTypeName, &nozzle));
  }
  const PaintNozzleData& Row(ObjectId id) const {
    return scene.row<PaintNozzleData>(nozzle, id, "paint nozzle");
  }
};

TEST(PaintNozzleTypeTest, RadiusScalesWithTheModel) {
  Fixture f;
  const ObjectId root = f.scene.AddDummy("bot", {}, {});
  PaintNozzleData nozzle;
  nozzle.radius = 0.02;
  const ObjectId pen = f.scene.AddObject(f.nozzle, "pen", root, {}, &nozzle);
  f.scene.ScaleSubtree(root, 2);
  EXPECT_DOUBLE_EQ(f.Row(pen).radius, 0.04);
  EXPECT_DOUBLE_EQ(f.scene.size_factor(pen), 2);
}

TEST(PaintNozzleTypeTest, ACopyKeepsColourAndState) {
  Fixture f;
  const ObjectId root = f.scene.AddDummy("bot", {}, {});
  PaintNozzleData nozzle;
  nozzle.color = {1, 0, 0};
  nozzle.enabled = false;
  f.scene.AddObject(f.nozzle, "pen", root, {}, &nozzle);
  const ObjectId copy = f.scene.DuplicateSubtree(root, {});
  const PaintNozzleData& copied = f.Row(f.scene.FindObject("./pen", copy));
  EXPECT_DOUBLE_EQ(copied.color.x, 1);
  EXPECT_DOUBLE_EQ(copied.color.z, 0);
  EXPECT_FALSE(copied.enabled);
}

}  // namespace
}  // namespace swarmsim
