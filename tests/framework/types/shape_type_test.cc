// The shape type (framework/types/shape_type.cc): each kind takes its own
// size keys, a key of another kind is refused at its line, a user's inertia
// must be physical, and a shape scales with its model (mass s^3, inertia s^5).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/types/core_types.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fake_reader.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;
using testing::FakeReader;

ShapeData Read(const FakeReader& reader) {
  Shared<ShapeData> shape;  // the type's row: settings shared by copies
  kShapeType.read(kShapeType, reader, &shape);
  return *shape;
}

TEST(ShapeTypeTest, EachKindReadsItsOwnSizeKeys) {
  const ShapeData box =
      Read(FakeReader{{"shape", std::string("box")}, {"size", std::vector<double>{1, 2, 3}}});
  EXPECT_EQ(box.kind, ShapeKind::kBox);
  EXPECT_EQ(box.size.x, 1);
  EXPECT_EQ(box.size.y, 2);
  EXPECT_EQ(box.size.z, 3);
  const ShapeData cylinder =
      Read(FakeReader{{"shape", std::string("cylinder")}, {"radius", 0.2}, {"height", 0.5}});
  EXPECT_EQ(cylinder.kind, ShapeKind::kCylinder);
  EXPECT_EQ(cylinder.size.x, 0.2);
  EXPECT_EQ(cylinder.size.z, 0.5);
  const ShapeData sphere = Read(FakeReader{{"shape", std::string("sphere")}, {"radius", 0.3}});
  EXPECT_EQ(sphere.kind, ShapeKind::kSphere);
  EXPECT_EQ(sphere.size.x, 0.3);
  const ShapeData capsule =
      Read(FakeReader{{"shape", std::string("capsule")}, {"radius", 0.1}, {"height", 0.2}});
  EXPECT_EQ(capsule.kind, ShapeKind::kCapsule);
  EXPECT_EQ(capsule.size.z, 0.2);  // exactly two radii: a sphere-ended disc is fine
}

TEST(ShapeTypeTest, TheOtherKeysReachTheRow) {
  const ShapeData s = Read(FakeReader{{"shape", std::string("sphere")},
                                      {"radius", 0.05},
                                      {"dynamic", true},
                                      {"mass", 0.4},
                                      {"collidable", false},
                                      {"visible", false},
                                      {"friction", 0.2},
                                      {"restitution", 0.5},
                                      {"color", std::vector<double>{1, 0, 0.5}},
                                      {"inertia", std::vector<double>{1, 2, 2, 0, 0, 0}}});
  EXPECT_TRUE(s.dynamic);
  EXPECT_EQ(s.mass, 0.4);
  EXPECT_FALSE(s.collidable);
  EXPECT_FALSE(s.visible);
  EXPECT_EQ(s.friction, 0.2);
  EXPECT_EQ(s.restitution, 0.5);
  EXPECT_EQ(s.color.x, 1);
  EXPECT_EQ(s.color.z, 0.5);
  EXPECT_FALSE(s.mesh_colors);  // a colour given replaces the mesh's own
  EXPECT_EQ(s.inertia, (std::array<double, 6>{1, 2, 2, 0, 0, 0}));
  // Without the keys: static, 1 kg, collidable, grey, inertia from the geometry.
  const ShapeData d = Read(FakeReader{{"shape", std::string("sphere")}, {"radius", 0.05}});
  EXPECT_FALSE(d.dynamic);
  EXPECT_EQ(d.mass, 1);
  EXPECT_TRUE(d.collidable);
  EXPECT_TRUE(d.visible);
  EXPECT_EQ(d.friction, 0.7);
  EXPECT_EQ(d.color.y, 0.7);
  EXPECT_EQ(d.inertia, (std::array<double, 6>{}));
}

TEST(ShapeTypeTest, AKeyOfAnotherKindIsRefusedAtThatKey) {
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"shape", std::string("box")},
                              {"size", std::vector<double>{1, 1, 1}},
                              {"radius", 0.1}});
            }),
            "model.yaml:4:1: 'radius' does not apply to a box (a box takes 'size: [x, y, z]')");
  EXPECT_EQ(
      ErrorOf([] {
        Read(FakeReader{
            {"shape", std::string("sphere")}, {"radius", 0.1}, {"file", std::string("part.stl")}});
      }),
      "model.yaml:4:1: 'file' does not apply to a sphere (only a mesh takes 'file: "
      "part.stl')");
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"shape", std::string("cylinder")},
                              {"size", std::vector<double>{1, 1, 1}}});
            }),
            "model.yaml:3:1: 'size' does not apply to a cylinder (a cylinder takes 'radius' and "
            "'height')");
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"shape", std::string("mesh")}, {"radius", 0.1}});
            }),
            "model.yaml:3:1: 'radius' does not apply to a mesh (a mesh takes 'file: "
            "part.stl|part.obj' and optionally 'scale: [sx, sy, sz]')");
  // A required size key missing, and no shape at all.
  EXPECT_CONTAINS(ErrorOf([] {
                    Read(FakeReader{{"shape", std::string("box")}});
                  }),
                  "missing 'size'");
  EXPECT_CONTAINS(ErrorOf([] { Read(FakeReader{}); }), "missing 'shape'");
}

TEST(ShapeTypeTest, ACapsuleIsAtLeastTwoRadiiHigh) {
  EXPECT_EQ(
      ErrorOf([] {
        Read(FakeReader{{"shape", std::string("capsule")}, {"radius", 0.1}, {"height", 0.19}});
      }),
      "model.yaml:4:3: a capsule's height includes its caps: it must be at least twice "
      "its radius");
}

TEST(ShapeTypeTest, InertiaMustBePositiveDefiniteAndObeyTheTriangleInequality) {
  EXPECT_TRUE(InertiaIsValid({1, 1, 1, 0, 0, 0}));
  EXPECT_TRUE(InertiaIsValid({1, 1, 2, 0, 0, 0}));  // a flat disc: on the edge
  EXPECT_FALSE(InertiaIsValid({1, 1, 2.1, 0, 0, 0}));
  EXPECT_FALSE(InertiaIsValid({0, 1, 1, 0, 0, 0}));
  EXPECT_FALSE(InertiaIsValid({-1, 1, 1, 0, 0, 0}));
  EXPECT_TRUE(InertiaIsValid({2, 2, 2, 0.5, 0, 0}));
  EXPECT_FALSE(InertiaIsValid({1, 1, 1, 1, 0, 0}));  // singular: xx yy - xy^2 = 0
  EXPECT_FALSE(InertiaIsValid({1, 1, 1, 0, 0, NAN}));
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"shape", std::string("sphere")},
                              {"radius", 0.1},
                              {"inertia", std::vector<double>{1, 1, 3, 0, 0, 0}}});
            }),
            "model.yaml:4:3: 'inertia' [ixx, iyy, izz, ixy, ixz, iyz] must be positive "
            "definite, each principal moment at most the sum of the other two");
}

TEST(ShapeTypeTest, ScalingScalesSizeMassInertiaAndSurfaceSpeed) {
  Scene scene;
  ShapeData belt;
  belt.size = {1, 0.2, 0.1};
  belt.mass = 2;
  belt.inertia = {1, 1, 1, 0, 0, 0};
  const ObjectId id = scene.AddShape("belt", {}, {}, belt);
  scene.SetSurfaceVelocity(id, {0.5, 0, 0}, {0, 0, 0.25});
  scene.ScaleSubtree(id, 2);
  const ShapeData& s = scene.shape(id);
  EXPECT_DOUBLE_EQ(s.size.x, 2);
  EXPECT_DOUBLE_EQ(s.size.z, 0.2);
  EXPECT_DOUBLE_EQ(s.mass, 16);
  EXPECT_DOUBLE_EQ(s.inertia[0], 32);  // kg m^2: s^3 of mass, s^2 of length
  EXPECT_DOUBLE_EQ(s.surface_velocity.x, 1);
  EXPECT_DOUBLE_EQ(s.surface_angular_velocity.z, 0.25);  // rad/s: unchanged
}

}  // namespace
}  // namespace swarmsim
