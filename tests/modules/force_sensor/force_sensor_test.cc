// Force sensors through a World: the reading under a hanging mass (ODE),
// breaking at the threshold after N steps, averaging, duplication with the
// model, and the Box2D weld.
#include "modules/force_sensor/force_sensor.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"

namespace swarmsim {
namespace {

constexpr double kGravity = 9.81;
constexpr double kMass = 2.0;  // kg, the hanging sphere

struct Fixture {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  explicit Fixture(std::string physics = "ode") {
    RegisterBuiltinModules(&registry);
    WorldSettings s;
    s.physics = std::move(physics);
    s.time_step = 0.01;
    s.physics_substeps = 2;
    s.gravity = kGravity;
    s.threads = 1;
    world = std::make_unique<World>(s, registry);
    world->set_log_sink([](std::string_view) {});
  }
  Scene& scene() { return world->scene(); }
};

ShapeData Shape(ShapeKind kind, const Vec3& size, bool dynamic, double mass = 1) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  s.dynamic = dynamic;
  s.mass = mass;
  return s;
}

// A force sensor (modules/force_sensor's type) under `parent`.
ObjectId AddForceSensor(Scene* scene, std::string name, ObjectId parent, const Pose& X_PO,
                        const ForceSensorData& settings) {
  ObjectType type;
  EXPECT_TRUE(force_sensor::FindType(*scene, &type));
  return scene->AddObject(type, std::move(name), parent, X_PO, &settings);
}

// A static beam at z = 2 with a force sensor under it holding a sphere
// 0.3 m below. Returns the sensor.
ObjectId HangMass(Scene* scene, const ForceSensorData& settings, ObjectId* mass = nullptr,
                  ObjectId* beam_out = nullptr) {
  const ObjectId beam =
      scene->AddShape("beam", {}, {{0, 0, 2}, {}}, Shape(ShapeKind::kBox, {0.2, 0.2, 0.05}, false));
  const ObjectId sensor = AddForceSensor(scene, "sensor", beam, {{0, 0, -0.05}, {}}, settings);
  const ObjectId ball = scene->AddShape("ball", sensor, {{0, 0, -0.25}, {}},
                                        Shape(ShapeKind::kSphere, {0.05, 0, 0}, true, kMass));
  if (mass) *mass = ball;
  if (beam_out) *beam_out = beam;
  return sensor;
}

TEST(ForceSensorTest, ReadsWeightOfHangingMassInOde) {
  Fixture f;
  ObjectId ball;
  const ObjectId sensor = HangMass(&f.scene(), {}, &ball);
  f.world->Start();
  for (int i = 0; i < 100; ++i) f.world->Step();
  const ForceSensorData& s = force_sensor::Row(f.scene(), sensor);
  ASSERT_TRUE(s.has_reading);
  EXPECT_FALSE(s.broken);
  // The parent holds the child up: +m g along the sensor's z.
  EXPECT_NEAR(s.force.z, kMass * kGravity, 0.01 * kMass * kGravity);
  EXPECT_NEAR(s.force.x, 0, 1e-3);
  EXPECT_NEAR(s.force.y, 0, 1e-3);
  EXPECT_NEAR(s.torque.Norm(), 0, 1e-3);
  EXPECT_NEAR(f.scene().world_pose(ball).p.z, 1.7, 1e-3);  // still held
}

// A box standing on a static table through a force sensor on the table's
// top: the link, not a contact between the box and the table, carries the
// box (its weight read in full); once the link breaks, the table holds the
// box up by contact.
TEST(ForceSensorTest, ReadsTheWeightOfAMassRestingOnItsStaticParentInOde) {
  Fixture f;
  const ObjectId table = f.scene().AddShape("table", {}, {{0, 0, 0.25}, {}},
                                            Shape(ShapeKind::kBox, {1, 1, 0.5}, false));
  ForceSensorData settings;
  settings.force_threshold = 1000;  // N: held at first (broken below by lowering it)
  const ObjectId sensor = AddForceSensor(&f.scene(), "sensor", table, {{0, 0, 0.25}, {}}, settings);
  const ObjectId box = f.scene().AddShape("box", sensor, {{0, 0, 0.1}, {}},
                                          Shape(ShapeKind::kBox, {0.2, 0.2, 0.2}, true, kMass));
  f.world->Start();
  for (int i = 0; i < 100; ++i) f.world->Step();
  const ForceSensorData& s = force_sensor::Row(f.scene(), sensor);
  ASSERT_TRUE(s.has_reading);
  EXPECT_NEAR(s.force.z, kMass * kGravity, 0.01 * kMass * kGravity);
  force_sensor::RowsOf(&f.scene())->rows[f.scene().row_at(sensor.index())].force_threshold =
      1;  // N: breaks now
  for (int i = 0; i < 100; ++i) f.world->Step();
  EXPECT_TRUE(force_sensor::Row(f.scene(), sensor).broken);
  EXPECT_NEAR(f.scene().world_pose(box).p.z, 0.6, 2e-3) << "on the table, not through it";
}

TEST(ForceSensorTest, TorqueOfOffsetMassAboutSensorOrigin) {
  Fixture f;
  const ObjectId beam = f.scene().AddShape("beam", {}, {{0, 0, 2}, {}},
                                           Shape(ShapeKind::kBox, {0.2, 0.2, 0.05}, false));
  const ObjectId sensor = AddForceSensor(&f.scene(), "sensor", beam, {{0, 0, -0.05}, {}}, {});
  // Mass 0.2 m out along +x: gravity pulls it down, the sensor holds it
  // with torque r x F = (0.2, 0, 0) x (0, 0, m g) = (0, -0.2 m g, 0).
  f.scene().AddShape("ball", sensor, {{0.2, 0, -0.1}, {}},
                     Shape(ShapeKind::kSphere, {0.05, 0, 0}, true, kMass));
  f.world->Start();
  for (int i = 0; i < 50; ++i) f.world->Step();
  const ForceSensorData& s = force_sensor::Row(f.scene(), sensor);
  EXPECT_NEAR(s.force.z, kMass * kGravity, 0.02 * kMass * kGravity);
  EXPECT_NEAR(s.torque.y, -0.2 * kMass * kGravity, 0.02 * 0.2 * kMass * kGravity);
}

TEST(ForceSensorTest, BreaksAfterThresholdExceededForNConsecutiveSteps) {
  Fixture f;
  ForceSensorData settings;
  settings.force_threshold = 15;  // N, below m g = 19.6 N
  settings.break_after = 5;
  ObjectId ball;
  const ObjectId sensor = HangMass(&f.scene(), settings, &ball);
  f.world->Start();
  for (int i = 1; i <= 4; ++i) {
    f.world->Step();
    EXPECT_FALSE(force_sensor::Row(f.scene(), sensor).broken) << "step " << i;
    EXPECT_EQ(force_sensor::Row(f.scene(), sensor).violations, i);
  }
  f.world->Step();
  EXPECT_TRUE(force_sensor::Row(f.scene(), sensor).broken);
  // Broken: the mass falls.
  for (int i = 0; i < 20; ++i) f.world->Step();
  EXPECT_LT(f.scene().world_pose(ball).p.z, 1.6);
}

TEST(ForceSensorTest, HoldsBelowThreshold) {
  Fixture f;
  ForceSensorData settings;
  settings.force_threshold = 25;  // N, above m g
  settings.break_after = 1;
  ObjectId ball;
  const ObjectId sensor = HangMass(&f.scene(), settings, &ball);
  f.world->Start();
  for (int i = 0; i < 100; ++i) f.world->Step();
  EXPECT_FALSE(force_sensor::Row(f.scene(), sensor).broken);
  EXPECT_EQ(force_sensor::Row(f.scene(), sensor).violations, 0);
  EXPECT_NEAR(f.scene().world_pose(ball).p.z, 1.7, 1e-3);
}

TEST(ForceSensorTest, FilterAveragesTheLastSamples) {
  ForceSensorData s;
  s.filter_samples = 3;
  RecordForceSensorSample(&s, {3, 0, 0}, {});
  EXPECT_DOUBLE_EQ(s.force.x, 3);
  RecordForceSensorSample(&s, {6, 0, 0}, {});
  EXPECT_DOUBLE_EQ(s.force.x, 4.5);
  RecordForceSensorSample(&s, {9, 0, 0}, {});
  EXPECT_DOUBLE_EQ(s.force.x, 6);
  RecordForceSensorSample(&s, {12, 0, 0}, {0, 0, 3});  // 3 drops out
  EXPECT_DOUBLE_EQ(s.force.x, 9);
  EXPECT_DOUBLE_EQ(s.torque.z, 1);
}

TEST(ForceSensorTest, DuplicatedWithItsModel) {
  Fixture f;
  ForceSensorData settings;
  settings.force_threshold = 25;
  settings.break_after = 3;
  ObjectId beam;
  const ObjectId sensor = HangMass(&f.scene(), settings, nullptr, &beam);
  f.scene().MakeModelInstance(beam, "hanger", "hanger#0");
  const ObjectId copy = f.scene().DuplicateSubtree(beam, {});
  f.scene().MakeModelInstance(copy, "hanger", "hanger#1");
  f.scene().SetLocalPose(copy, {{1, 0, 2}, {}});
  const ObjectId copy_sensor = f.scene().FindObject("./sensor", copy);
  ASSERT_FALSE(copy_sensor.IsNull());
  ASSERT_NE(copy_sensor, sensor);
  const ForceSensorData& c = force_sensor::Row(f.scene(), copy_sensor);
  EXPECT_EQ(c.break_after, 3);
  EXPECT_EQ(c.force_threshold, 25);
  f.world->Start();
  for (int i = 0; i < 100; ++i) f.world->Step();
  EXPECT_NEAR(force_sensor::Row(f.scene(), sensor).force.z, kMass * kGravity, 0.2);
  EXPECT_NEAR(force_sensor::Row(f.scene(), copy_sensor).force.z, kMass * kGravity, 0.2);
  const ObjectId copy_ball = f.scene().FindObject("./ball", copy);
  EXPECT_NEAR(f.scene().world_pose(copy_ball).p.x, 1, 1e-3);
}

TEST(ForceSensorTest, Box2dWeldHoldsAndReads) {
  Fixture f("box2d");
  const ObjectId body = f.scene().AddShape("body", {}, {{0, 0, 0.05}, {}},
                                           Shape(ShapeKind::kBox, {0.2, 0.2, 0.1}, true, 1));
  const ObjectId sensor = AddForceSensor(&f.scene(), "sensor", body, {{0.15, 0, 0}, {}}, {});
  const ObjectId tail = f.scene().AddShape("tail", sensor, {{0.1, 0, 0}, {}},
                                           Shape(ShapeKind::kBox, {0.1, 0.1, 0.1}, true, 1));
  f.world->Start();
  f.scene().SetWorldPose(body, {{0, 0, 0.05}, {}});
  for (int i = 0; i < 10; ++i) f.world->Step();
  const ForceSensorData& s = force_sensor::Row(f.scene(), sensor);
  EXPECT_TRUE(s.has_reading);
  EXPECT_FALSE(s.broken);
  EXPECT_NEAR(f.scene().world_pose(tail).p.x - f.scene().world_pose(body).p.x, 0.25, 1e-3);
}

}  // namespace
}  // namespace swarmsim
