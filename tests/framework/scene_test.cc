#include "framework/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "framework/error.h"
#include "modules/proximity/proximity_sensor.h"

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
  j.settings.Edit().type = JointType::kRevolute;
  const ObjectId joint = scene.AddJoint("j", {}, {}, j);
  const ObjectId arm = scene.AddDummy("arm", joint, {{1, 0, 0}, {}});
  scene.mutable_joint(joint).position = M_PI / 2;
  scene.UpdateWorldPoses();
  ExpectNear(scene.world_pose(arm).p, {0, 1, 0});

  JointData p;
  p.settings.Edit().type = JointType::kPrismatic;
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

// --- The post-physics pose update ---------------------------------------------

// World pose of `slot` composed from scratch, frame by frame, from the local
// poses and joint motions: what UpdateWorldPoses must produce, bit for bit.
Pose ReferenceWorldPose(const Scene& scene, uint32_t slot) {
  const int32_t p = scene.parent_at(slot);
  if (p < 0) return scene.local_pose_at(slot);
  Pose X_WF = ReferenceWorldPose(scene, static_cast<uint32_t>(p));
  if (scene.type_at(static_cast<uint32_t>(p)) == ObjectType::kJoint)
    X_WF = X_WF * scene.joints()[scene.row_at(static_cast<uint32_t>(p))].Motion();
  return X_WF * scene.local_pose_at(slot);
}

bool SameBits(const Pose& a, const Pose& b) { return std::memcmp(&a, &b, sizeof(Pose)) == 0; }

// A foot-bot-like robot whose tree makes the update switch frames often: a
// body with a wheel joint, half a ring of 12 sensors, a two-joint arm with a
// gripper and a sensor on it, the other half of the ring, and a prismatic
// joint carrying two children.
struct RingBot {
  ObjectId body, wheel_joint, wheel, arm_base, arm_elbow, gripper, slider;
  std::vector<ObjectId> ring;
};

RingBot AddRingBot(Scene* scene, const std::string& name, const Pose& X_WB) {
  RingBot bot;
  ShapeData body;
  body.kind = ShapeKind::kCylinder;
  body.dynamic = true;
  bot.body = scene->AddShape(name, {}, X_WB, body);
  scene->MakeModelInstance(bot.body, "ringbot", name);
  JointData revolute;
  bot.wheel_joint =
      scene->AddJoint("wheelMotor", bot.body,
                      {{0, 0.07, -0.04}, Quat::FromAxisAngle({1, 0, 0}, -M_PI / 2)}, revolute);
  bot.wheel = scene->AddDummy("wheel", bot.wheel_joint, {});
  auto add_sensors = [&](int from, int to) {
    for (int i = from; i < to; ++i) {
      const double a = i * M_PI / 12;
      const Quat q_BS = Quat::FromYaw(a) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
      bot.ring.push_back(proximity::AddSensor(
          scene, "prox", bot.body, {{0.085 * std::cos(a), 0.085 * std::sin(a), -0.013}, q_BS}, {}));
    }
  };
  add_sensors(0, 12);
  bot.arm_base = scene->AddJoint("armBase", bot.body, {{0.02, 0, 0.07}, {}}, revolute);
  bot.arm_elbow = scene->AddJoint(
      "armElbow", bot.arm_base, {{0.1, 0, 0}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)}, revolute);
  bot.gripper = scene->AddDummy("gripper", bot.arm_elbow, {{0.08, 0, 0}, {}});
  proximity::AddSensor(scene, "gripperProx", bot.gripper, {{0.01, 0, 0}, {}}, {});
  add_sensors(12, 24);
  JointData prismatic;
  prismatic.settings.Edit().type = JointType::kPrismatic;
  bot.slider = scene->AddJoint("slider", bot.body, {{0, 0, 0.08}, {}}, prismatic);
  scene->AddDummy("carriage", bot.slider, {{0, 0.01, 0}, {}});
  scene->AddDummy("carriageTip", bot.slider, {{0, 0.02, 0.01}, Quat::FromYaw(0.3)});
  return bot;
}

// Moves `bot` as a backend and the actuate phase would: new body state, new
// joint positions.
void MoveRingBot(Scene* scene, const RingBot& bot, double t) {
  scene->SetSimulatedState(bot.body.index(),
                           {{1 + 0.3 * t, -2 + 0.1 * t * t, 0.05},
                            Quat::FromYaw(0.7 * t) * Quat::FromAxisAngle({1, 0, 0}, 0.01 * t)},
                           {0.3, 0.2 * t, 0}, {0, 0, 0.7});
  scene->mutable_joint(bot.wheel_joint).position = 1.7 * t;
  scene->mutable_joint(bot.arm_base).position = -0.4 * t;
  scene->mutable_joint(bot.arm_elbow).position = 0.9 * t;
  scene->mutable_joint(bot.slider).position = 0.01 * t;
}

void ExpectAllPosesComposedExactly(const Scene& scene) {
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    if (!scene.alive_at(s)) continue;
    EXPECT_TRUE(SameBits(scene.world_pose_at(s), ReferenceWorldPose(scene, s)))
        << scene.PathOf(scene.IdAt(s));
  }
}

TEST(SceneTest, PoseUpdateOfMovedRobotsEqualsComposingEveryFrame) {
  // Two robots and a scene object, moved and updated per instance (as
  // World::Physics does) over several steps: every object's world pose,
  // sensors, wheel and arm included, must be the frame-by-frame composition.
  Scene scene;
  const RingBot a = AddRingBot(&scene, "a#0", {{0, 0, 0.05}, {}});
  const RingBot b = AddRingBot(&scene, "a#1", {{1, 1, 0.05}, Quat::FromYaw(2.0)});
  const ObjectId landmark = scene.AddDummy("landmark", {}, {{3, 0, 0}, {}});
  scene.AddDummy("flag", landmark, {{0, 0, 1}, Quat::FromYaw(0.5)});
  ASSERT_TRUE(scene.InstancesAreIndependent());
  for (int step = 1; step <= 3; ++step) {
    MoveRingBot(&scene, a, 0.1 * step);
    MoveRingBot(&scene, b, -0.2 * step);
    scene.UpdateWorldPoses(1);
    scene.UpdateWorldPoses(0);
    scene.UpdateSceneObjectPoses();
    ExpectAllPosesComposedExactly(scene);
    // The bodies keep the pose the backend wrote; their local pose follows.
    EXPECT_TRUE(SameBits(scene.local_pose(a.body), scene.world_pose(a.body)));
  }
  // Spot check against plain geometry: the first sensor sits 8.5 cm along
  // the body's heading.
  const Pose& X_WB = scene.world_pose(a.body);
  const Vec3 p_WS = scene.world_pose(a.ring[0]).p;
  const Vec3 expected = X_WB * Vec3{0.085, 0, -0.013};
  EXPECT_NEAR(p_WS.x, expected.x, 1e-15);
  EXPECT_NEAR(p_WS.y, expected.y, 1e-15);
  EXPECT_NEAR(p_WS.z, expected.z, 1e-15);
}

TEST(SceneTest, WholeScenePoseUpdateEqualsPerInstanceUpdate) {
  Scene whole, split;
  const RingBot w0 = AddRingBot(&whole, "r#0", {{0, 0, 0.05}, {}});
  const RingBot w1 = AddRingBot(&whole, "r#1", {{2, 0, 0.05}, Quat::FromYaw(-1)});
  const RingBot s0 = AddRingBot(&split, "r#0", {{0, 0, 0.05}, {}});
  const RingBot s1 = AddRingBot(&split, "r#1", {{2, 0, 0.05}, Quat::FromYaw(-1)});
  MoveRingBot(&whole, w0, 0.3);
  MoveRingBot(&whole, w1, 0.6);
  MoveRingBot(&split, s0, 0.3);
  MoveRingBot(&split, s1, 0.6);
  whole.UpdateWorldPoses();
  split.UpdateWorldPoses(0);
  split.UpdateWorldPoses(1);
  split.UpdateSceneObjectPoses();
  ASSERT_EQ(whole.slot_count(), split.slot_count());
  for (uint32_t s = 0; s < whole.slot_count(); ++s) {
    EXPECT_TRUE(SameBits(whole.world_pose_at(s), split.world_pose_at(s))) << whole.name_at(s);
    EXPECT_TRUE(SameBits(whole.local_pose_at(s), split.local_pose_at(s))) << whole.name_at(s);
  }
  ExpectAllPosesComposedExactly(whole);
}

TEST(SceneTest, SimulatedObjectUnderAJointKeepsItsPoseAndCarriesItsChildren) {
  // A body simulated below a joint (an ODE-style arm link): the update keeps
  // its world pose, derives its local pose through the joint's motion, and
  // moves what hangs from it.
  Scene scene;
  JointData revolute;
  const ObjectId joint = scene.AddJoint("j", {}, {{0, 0, 1}, Quat::FromYaw(0.2)}, revolute);
  const ObjectId sibling = scene.AddDummy("before", joint, {{0.1, 0, 0}, {}});
  const ObjectId link = scene.AddDummy("link", joint, {{0.5, 0, 0}, {}});
  const ObjectId tip = scene.AddDummy("tip", link, {{0.2, 0.1, 0}, Quat::FromYaw(-0.4)});
  scene.mutable_joint(joint).position = 0.8;
  const Pose X_WL{{0.3, 0.4, 1.1}, Quat::FromRollPitchYaw(0.1, -0.2, 1.3)};
  scene.SetSimulatedState(link.index(), X_WL, {}, {});
  scene.UpdateWorldPoses();
  EXPECT_TRUE(SameBits(scene.world_pose(link), X_WL));
  const Pose X_WF = scene.world_pose(joint) * scene.joint(joint).Motion();
  EXPECT_TRUE(SameBits(scene.local_pose(link), X_WF.Inverse() * X_WL));
  EXPECT_TRUE(SameBits(scene.world_pose(tip), X_WL * scene.local_pose(tip)));
  EXPECT_TRUE(SameBits(scene.world_pose(sibling), X_WF * scene.local_pose(sibling)));
  // Next update, not simulated: the link follows its (new) local pose.
  scene.mutable_joint(joint).position = 1.0;
  scene.UpdateWorldPoses();
  ExpectAllPosesComposedExactly(scene);
}

}  // namespace
}  // namespace swarmsim
