// What the renderer draws (modules/rendering/geometry.cc): one item of
// world-frame triangles per shape and LED (per object whose type declares a
// solid or light visual), in row order, with unit normals
// facing out, the shape's colour, a bounding sphere that holds them, LEDs
// drawn unlit and at least a given size, and the scene's bounds.
#include "modules/rendering/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "framework/object_type.h"
#include "modules/blobs/leds.h"
#include "tests/modules/module_world.h"

namespace swarmsim::rendering {
namespace {

using testing::ModuleWorld;

const DrawItem* ItemOf(const DrawList& list, uint32_t slot) {
  for (const DrawItem& item : list.items)
    if (item.slot == slot) return &item;
  return nullptr;
}

Vec3 Vertex(const DrawList& list, uint32_t v) {
  return {list.xyz[3 * v], list.xyz[3 * v + 1], list.xyz[3 * v + 2]};
}

TEST(RenderGeometryTest, ABoxIsTwelveTrianglesInTheWorldFrame) {
  ModuleWorld w;
  ShapeData box;
  box.kind = ShapeKind::kBox;
  box.size = {2, 1, 1};
  box.color = {1, 0, 0};
  const ObjectId id = w.scene().AddShape("box", {}, {{1, 2, 0.5}, Quat::FromYaw(M_PI / 2)}, box);
  ASSERT_EQ(w.Run(0), "");
  DrawList list;
  BuildDrawList(w.world(), 16, &list);
  const DrawItem* item = ItemOf(list, w.scene().SlotOf(id));
  ASSERT_NE(item, nullptr);
  EXPECT_EQ(item->count, 36u);
  EXPECT_FALSE(item->emissive);
  // Turned a quarter: 1 m along x, 2 m along y, around (1, 2, 0.5).
  for (uint32_t v = item->first; v < item->first + item->count; ++v) {
    const Vec3 p = Vertex(list, v);
    EXPECT_NEAR(std::abs(p.x - 1), 0.5, 1e-6);
    EXPECT_LE(std::abs(p.y - 2), 1 + 1e-6);
    EXPECT_NEAR(std::abs(p.z - 0.5), 0.5, 1e-6);
    const Vec3 n{list.normal[3 * v], list.normal[3 * v + 1], list.normal[3 * v + 2]};
    EXPECT_NEAR(n.Norm(), 1, 1e-6);
    EXPECT_EQ(list.rgb[3 * v], 255);
    EXPECT_EQ(list.rgb[3 * v + 1], 0);
    const Vec3 centre{item->center[0], item->center[1], item->center[2]};
    EXPECT_LE((p - centre).Norm(), item->radius + 1e-5);
  }
  // Each triangle is wound so that its normal points away from the centre.
  for (uint32_t v = item->first; v < item->first + item->count; v += 3) {
    const Vec3 a = Vertex(list, v), b = Vertex(list, v + 1), c = Vertex(list, v + 2);
    const Vec3 facing = (b - a).Cross(c - a);
    EXPECT_GT(facing.Dot((a + b + c) * (1.0 / 3) - Vec3{1, 2, 0.5}), 0);
  }
  ASSERT_TRUE(list.has_bounds);
  EXPECT_NEAR(list.lo.x, 0.5, 1e-9);
  EXPECT_NEAR(list.hi.y, 3, 1e-9);
  EXPECT_NEAR(list.hi.z, 1, 1e-9);
}

TEST(RenderGeometryTest, ItemsFollowTheSlotsAndTheSameSceneGivesTheSameArrays) {
  ModuleWorld w;
  ShapeData ball;
  ball.kind = ShapeKind::kSphere;
  ball.size = {0.2, 0, 0};
  const ObjectId first = w.scene().AddShape("a", {}, {{0, 0, 1}, {}}, ball);
  const ObjectId second = w.scene().AddShape("b", {}, {{1, 0, 1}, {}}, ball);
  ASSERT_EQ(w.Run(0), "");
  DrawList one, two;
  BuildDrawList(w.world(), 12, &one);
  BuildDrawList(w.world(), 12, &two);
  EXPECT_EQ(one.xyz, two.xyz);
  EXPECT_EQ(one.rgb, two.rgb);
  const DrawItem* a = ItemOf(one, w.scene().SlotOf(first));
  const DrawItem* b = ItemOf(one, w.scene().SlotOf(second));
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_LT(a->first, b->first);
  // A sphere's vertices lie on it.
  for (uint32_t v = a->first; v < a->first + a->count; ++v)
    EXPECT_NEAR((Vertex(one, v) - Vec3{0, 0, 1}).Norm(), 0.2, 1e-6);
  // More segments, more triangles.
  DrawList fine;
  BuildDrawList(w.world(), 24, &fine);
  EXPECT_GT(ItemOf(fine, w.scene().SlotOf(first))->count, a->count);
}

TEST(RenderGeometryTest, LedsAreUnlitAndAtLeastTheSizeAskedFor) {
  ModuleWorld w;
  const ObjectId bot = w.Robot("bot", {});
  LedRow led;
  led.color = {0, 1, 0};
  led.radius = 0.01;
  const ObjectId id = w.Add(kLedTypeName, "led", bot, {{0, 0, 0.2}, {}}, &led);
  ASSERT_EQ(w.Run(0), "");
  DrawList list;
  BuildDrawList(w.world(), 12, &list, /*min_led_radius=*/0.05);
  const DrawItem* item = ItemOf(list, w.scene().SlotOf(id));
  ASSERT_NE(item, nullptr);
  EXPECT_TRUE(item->emissive);
  EXPECT_EQ(list.rgb[3 * item->first + 1], 255);
  // A sphere at the LED: 5 cm (the least asked for), else its own 1 cm.
  const auto expect_radius = [&](const DrawList& l, const DrawItem& it, double radius) {
    for (uint32_t v = it.first; v < it.first + it.count; ++v)
      EXPECT_NEAR((Vertex(l, v) - Vec3{0, 0, 0.2}).Norm(), radius, 1e-6);
  };
  expect_radius(list, *item, 0.05);
  DrawList small;
  BuildDrawList(w.world(), 12, &small);
  expect_radius(small, *ItemOf(small, w.scene().SlotOf(id)), 0.01);
  // LEDs do not widen the scene's bounds.
  EXPECT_FALSE(small.has_bounds);
  // Switched off: not drawn lit (nothing, or not emissive).
  w.RowOf<LedRow>(kLedTypeName, id).on = false;
  DrawList off;
  BuildDrawList(w.world(), 12, &off);
  const DrawItem* dark = ItemOf(off, w.scene().SlotOf(id));
  EXPECT_TRUE(dark == nullptr || !dark->emissive);
}

// A test type that is drawn as its row says: what the renderer knows of a
// type is its visual declaration.
struct LookRow {
  VisualKind kind = VisualKind::kLight;
};
constinit const ObjectTypeDescriptor kLookType{
    .name = "look",
    .description = "a test type drawn as its row says",
    .make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
      return std::make_unique<Rows<LookRow>>();
    },
    .visual =
        [](const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
          out->kind = scene.rows<LookRow>(type).rows[row].kind;
          out->size = {0.5, 0.5, 0.5};
          out->color = {0, 1, 0};
        },
};

TEST(RenderGeometryTest, ATypeIsDrawnAsItsVisualDeclaresItAndRaysAreNot) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  registry.RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &kLookType));
  World world(WorldSettings{}, registry);
  Scene& scene = world.scene();
  ObjectType look{};
  ASSERT_TRUE(scene.FindType("look", &look));
  LookRow light, box, ray;
  box.kind = VisualKind::kBox;
  ray.kind = VisualKind::kRay;
  const ObjectId l = scene.AddObject(look, "light", {}, {{1, 0, 0}, {}}, &light);
  const ObjectId b = scene.AddObject(look, "box", {}, {{-1, 0, 0}, {}}, &box);
  const ObjectId r = scene.AddObject(look, "ray", {}, {}, &ray);
  DrawList list;
  BuildDrawList(world, 8, &list);
  const DrawItem* lit = ItemOf(list, scene.SlotOf(l));
  ASSERT_NE(lit, nullptr);
  EXPECT_TRUE(lit->emissive);
  EXPECT_EQ(list.rgb[3 * lit->first + 1], 255);
  const DrawItem* solid = ItemOf(list, scene.SlotOf(b));
  ASSERT_NE(solid, nullptr);
  EXPECT_FALSE(solid->emissive);
  EXPECT_EQ(solid->count, 36u);  // a box: 12 triangles
  EXPECT_EQ(ItemOf(list, scene.SlotOf(r)), nullptr);
}

}  // namespace
}  // namespace swarmsim::rendering
