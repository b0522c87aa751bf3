#include "framework/scene.h"

#include <gtest/gtest.h>

#include <cmath>

#include "framework/error.h"

namespace swarmsim {
namespace {

constexpr double kTol = 1e-12;

void ExpectNear(const Vec3& a, const Vec3& b, double tol = kTol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(PoseTest, CompositionReadsLikeTheMath) {
  // B is 1 m along W's x, turned 90 degrees about z; C is 1 m along B's x.
  const Pose X_WB{{1, 0, 0}, Quat::FromYaw(M_PI / 2)};
  const Pose X_BC{{1, 0, 0}, {}};
  const Pose X_WC = X_WB * X_BC;
  ExpectNear(X_WC.p, {1, 1, 0});
  EXPECT_NEAR(X_WC.q.Yaw(), M_PI / 2, kTol);
  // Inverse cancels.
  const Pose I = X_WB.Inverse() * X_WB;
  ExpectNear(I.p, {0, 0, 0});
  EXPECT_NEAR(I.q.w, 1, kTol);
  ExpectNear(X_WB.Inverse() * X_WC.p, X_BC.p);
}

TEST(PoseTest, RollPitchYawRoundTrip) {
  const Quat q = Quat::FromRollPitchYaw(0.3, -0.4, 2.5);
  const Vec3 rpy = q.RollPitchYaw();
  EXPECT_NEAR(rpy.x, 0.3, 1e-12);
  EXPECT_NEAR(rpy.y, -0.4, 1e-12);
  EXPECT_NEAR(rpy.z, 2.5, 1e-12);
}

TEST(SceneTest, StaleHandleIsRejected) {
  Scene scene;
  const ObjectId a = scene.AddDummy("a", {}, {});
  ASSERT_TRUE(scene.IsValid(a));
  scene.RemoveSubtree(a);
  EXPECT_FALSE(scene.IsValid(a));
  EXPECT_THROW(scene.world_pose(a), Error);
  // The slot is reused by the next object, with a new generation.
  const ObjectId b = scene.AddDummy("b", {}, {});
  EXPECT_EQ(b.index1, a.index1);
  EXPECT_NE(b.generation, a.generation);
  EXPECT_FALSE(scene.IsValid(a));
  EXPECT_TRUE(scene.IsValid(b));
  try {
    scene.name(a);
    FAIL() << "stale handle accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("stale"), std::string::npos) << e.what();
  }
  EXPECT_THROW(scene.name(ObjectId{}), Error);
  EXPECT_THROW(scene.name(ObjectId{999, 0}), Error);
}

TEST(SceneTest, HandlesRoundTripThroughIntegers) {
  const ObjectId id{7, 3};
  EXPECT_EQ(ObjectId::FromInteger(id.ToInteger()), id);
  EXPECT_EQ((ObjectId{5, 0}.ToInteger()), 5);
}

TEST(SceneTest, ChildWorldPoseFollowsParent) {
  Scene scene;
  const ObjectId base = scene.AddDummy("base", {}, {{1, 2, 0}, Quat::FromYaw(M_PI / 2)});
  const ObjectId tip = scene.AddDummy("tip", base, {{0.5, 0, 0}, {}});
  ExpectNear(scene.world_pose(tip).p, {1, 2.5, 0});
  scene.SetLocalPose(base, {{0, 0, 0}, {}});
  ExpectNear(scene.world_pose(tip).p, {0.5, 0, 0});
  scene.SetWorldPose(tip, {{3, 3, 3}, {}});
  ExpectNear(scene.local_pose(tip).p, {3, 3, 3});
}

TEST(SceneTest, JointMotionMovesChildren) {
  Scene scene;
  JointData j;
  j.type = JointType::kRevolute;
  const ObjectId joint = scene.AddJoint("j", {}, {}, j);
  const ObjectId arm = scene.AddDummy("arm", joint, {{1, 0, 0}, {}});
  scene.mutable_joint(joint).position = M_PI / 2;
  scene.UpdateWorldPoses();
  ExpectNear(scene.world_pose(arm).p, {0, 1, 0});

  JointData p;
  p.type = JointType::kPrismatic;
  const ObjectId slider =
      scene.AddJoint("s", {}, {{0, 0, 0}, Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)}, p);
  const ObjectId carriage = scene.AddDummy("c", slider, {});
  scene.mutable_joint(slider).position = 0.25;  // along the joint's z, i.e. world +x
  scene.UpdateWorldPoses();
  ExpectNear(scene.world_pose(carriage).p, {0.25, 0, 0});
}

TEST(SceneTest, TreeEditsKeepPosesAndRejectCycles) {
  Scene scene;
  const ObjectId a = scene.AddDummy("a", {}, {{1, 0, 0}, {}});
  const ObjectId b = scene.AddDummy("b", {}, {{0, 2, 0}, {}});
  const ObjectId c = scene.AddDummy("c", b, {{0, 0, 1}, {}});
  scene.SetParent(c, a, /*keep_world_pose=*/true);
  EXPECT_EQ(scene.parent(c), a);
  ExpectNear(scene.world_pose(c).p, {0, 2, 1});
  ExpectNear(scene.local_pose(c).p, {-1, 2, 1});
  EXPECT_TRUE(scene.children(b).empty());
  EXPECT_THROW(scene.SetParent(a, c, true), Error);  // a cycle
  scene.RemoveSubtree(a);
  EXPECT_FALSE(scene.IsValid(c));
  EXPECT_TRUE(scene.IsValid(b));
  EXPECT_EQ(scene.object_count(), 1u);
}

TEST(SceneTest, PathsResolveRelativeToTheCaller) {
  Scene scene;
  const ObjectId robot = scene.AddDummy("robot", {}, {});
  const ObjectId body = scene.AddDummy("body", robot, {});
  const ObjectId s0 = scene.AddDummy("sensor", body, {});
  const ObjectId s1 = scene.AddDummy("sensor", body, {});
  scene.MakeModelInstance(robot, "bot", "bot#0");
  EXPECT_EQ(scene.FindObject("/robot/body"), body);
  EXPECT_EQ(scene.FindObject("./sensor", body), s0);
  EXPECT_EQ(scene.FindObject("./sensor[1]", body), s1);
  EXPECT_EQ(scene.FindObject(":/sensor[1]", s0), s1);
  EXPECT_EQ(scene.FindObject(".", body), body);
  EXPECT_TRUE(scene.FindObject("./sensor[2]", body).IsNull());
  EXPECT_TRUE(scene.FindObject("/nothing").IsNull());
  EXPECT_THROW(scene.FindObject("./sensor[x]", body), Error);
  EXPECT_THROW(scene.FindObject("sensor", body), Error);
  EXPECT_EQ(scene.PathOf(s1), "/robot/body/sensor");
}

TEST(SceneTest, DuplicatingAModelCopiesObjectsScriptsAndRemapsReferences) {
  Scene scene;
  const ObjectId outside = scene.AddDummy("landmark", {}, {});
  ShapeData body_shape;
  body_shape.kind = ShapeKind::kCylinder;
  body_shape.dynamic = true;
  const ObjectId root = scene.AddShape("body", {}, {{1, 0, 0}, {}}, body_shape);
  const ObjectId motor = scene.AddJoint("motor", root, {{0, 0.1, 0}, {}}, JointData{});
  const ObjectId tip = scene.AddDummy("tip", motor, {});
  const ObjectId target = scene.AddDummy("target", root, {});
  const ObjectId beacon = scene.AddDummy("beacon", root, {});
  scene.LinkDummies(tip, target);      // internal reference
  scene.LinkDummies(beacon, outside);  // reference to outside the model
  auto source = std::make_shared<ScriptSource>(ScriptSource{"ctl.lua", "-- code"});
  scene.AttachScript(root, source);
  const int first = scene.MakeModelInstance(root, "bot", "bot#0");
  EXPECT_EQ(first, 0);

  const ObjectId copy = scene.DuplicateSubtree(root, {});
  ASSERT_EQ(scene.instances().size(), 2u);
  EXPECT_EQ(scene.instance_of(copy), 1);
  EXPECT_EQ(scene.instance(1).model_name, "bot");
  EXPECT_EQ(scene.instance(1).objects.size(), scene.instance(0).objects.size());
  // Objects copied, with their data.
  EXPECT_TRUE(scene.shape(copy).dynamic);
  const ObjectId copy_motor = scene.FindObject("./motor", copy);
  ASSERT_FALSE(copy_motor.IsNull());
  EXPECT_NE(copy_motor, motor);
  // Script copied, source shared (an asset, not a copy).
  ASSERT_NE(scene.script(copy), nullptr);
  EXPECT_EQ(scene.script(copy)->source.get(), source.get());
  // Internal link remapped to the copy; external link kept.
  const ObjectId copy_tip = scene.FindObject("./tip", copy);
  const ObjectId copy_target = scene.FindObject("./target", copy);
  EXPECT_EQ(scene.linked_dummy(copy_tip), copy_target);
  EXPECT_EQ(scene.linked_dummy(tip), target);
  EXPECT_EQ(scene.linked_dummy(scene.FindObject("./beacon", copy)), outside);
  // Every object of the copy belongs to the new instance.
  for (uint32_t s : scene.instance(1).objects) EXPECT_EQ(scene.instance_of_at(s), 1);

  // Deleting the copy deletes its objects and retires its instance.
  const size_t before = scene.object_count();
  scene.RemoveSubtree(copy);
  EXPECT_EQ(scene.object_count(), before - 5);
  EXPECT_FALSE(scene.instance(1).alive);
  EXPECT_FALSE(scene.IsValid(copy_tip));
  EXPECT_EQ(scene.linked_dummy(tip), target);
}

TEST(SceneTest, TypedAccessChecksTheType) {
  Scene scene;
  const ObjectId d = scene.AddDummy("d", {}, {});
  EXPECT_THROW(scene.joint(d), Error);
  EXPECT_THROW(scene.shape(d), Error);
  // Swap-removal keeps the other rows attached to the right objects.
  ShapeData s1, s2, s3;
  s1.mass = 1;
  s2.mass = 2;
  s3.mass = 3;
  const ObjectId a = scene.AddShape("a", {}, {}, s1);
  const ObjectId b = scene.AddShape("b", {}, {}, s2);
  const ObjectId c = scene.AddShape("c", {}, {}, s3);
  scene.RemoveSubtree(a);
  EXPECT_EQ(scene.shape(b).mass, 2);
  EXPECT_EQ(scene.shape(c).mass, 3);
  EXPECT_EQ(scene.shapes().size(), 2u);
}

}  // namespace
}  // namespace swarmsim
