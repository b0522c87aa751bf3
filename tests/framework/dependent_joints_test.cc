// Dependent joints (framework/dependent_joints.cc; V-REP's dependent mode,
// URDF's mimic): q = offset + factor * q_master every step, masters first,
// and load errors naming the file:line:column of the `master` key.
#include "framework/dependent_joints.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "framework/error.h"
#include "framework/scene.h"
#include "tests/framework/error_of.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;

JointData Follower(const std::string& master, double factor, double offset,
                   const std::string& where = "arm.yaml:7:13") {
  JointData j;
  auto d = std::make_shared<JointDependency>();
  d->master = master;
  d->factor = factor;
  d->offset = offset;
  d->where = where;
  j.settings.Edit().depends = std::move(d);
  return j;
}

// Joints added followers first, so row order is the reverse of the chain's.
TEST(DependentJointsTest, AChainResolvesMastersFirstInOnePass) {
  Scene scene;
  const ObjectId c = scene.AddJoint("c", {}, {}, Follower("/b", -1, 0.5));
  const ObjectId b = scene.AddJoint("b", {}, {}, Follower("/a", 2, 0.1));
  JointData driver;
  driver.position = 1;
  driver.velocity = 3;
  const ObjectId a = scene.AddJoint("a", {}, {}, driver);
  DependentJoints dependents;
  ASSERT_TRUE(dependents.Apply(&scene, /*targets=*/false));
  EXPECT_DOUBLE_EQ(scene.joint(b).position, 0.1 + 2 * 1);
  EXPECT_DOUBLE_EQ(scene.joint(b).velocity, 2 * 3);
  EXPECT_DOUBLE_EQ(scene.joint(c).position, 0.5 - (0.1 + 2 * 1));
  EXPECT_DOUBLE_EQ(scene.joint(c).velocity, -2 * 3);
  // The master moves: the next call follows.
  scene.mutable_joint(a).position = -0.25;
  dependents.Apply(&scene, false);
  EXPECT_DOUBLE_EQ(scene.joint(c).position, 0.5 - (0.1 + 2 * -0.25));
}

TEST(DependentJointsTest, ASimulatedFollowerGetsTheFormulaAsItsTarget) {
  Scene scene;
  JointData master;
  master.position = 0.3;
  scene.AddJoint("master", {}, {}, master);
  JointData follower = Follower("/master", 3, 0);
  follower.simulated = true;
  follower.position = 7;
  const ObjectId f = scene.AddJoint("follower", {}, {}, follower);
  DependentJoints dependents;
  dependents.Apply(&scene, /*targets=*/false);
  EXPECT_EQ(scene.joint(f).position, 7);  // the backend moves it
  EXPECT_EQ(scene.joint(f).target_position, 0);
  dependents.Apply(&scene, /*targets=*/true);
  EXPECT_DOUBLE_EQ(scene.joint(f).target_position, 0.9);
  EXPECT_EQ(scene.joint(f).position, 7);
}

TEST(DependentJointsTest, JointsAddedLaterAreFollowedToo) {
  Scene scene;
  JointData master;
  master.position = 2;
  const ObjectId m = scene.AddJoint("m", {}, {}, master);
  scene.MakeModelInstance(m, "arm", "arm#0");
  DependentJoints dependents;
  EXPECT_FALSE(dependents.Apply(&scene, false));                         // none yet
  const ObjectId f = scene.AddJoint("f", m, {}, Follower(":", 0.5, 0));  // its model's root
  EXPECT_TRUE(dependents.Apply(&scene, false));
  EXPECT_DOUBLE_EQ(scene.joint(f).position, 1);
  // A copy's follower follows the copy's master (the path is relative).
  const ObjectId m2 = scene.DuplicateSubtree(m, {});
  scene.mutable_joint(m2).position = 10;
  dependents.Apply(&scene, false);
  EXPECT_DOUBLE_EQ(scene.joint(scene.children(m2).at(0)).position, 5);
  EXPECT_DOUBLE_EQ(scene.joint(f).position, 1);
}

TEST(DependentJointsTest, BadMastersAreErrorsAtTheMasterKey) {
  Scene scene;
  const ObjectId base = scene.AddDummy("base", {}, {});
  const ObjectId missing = scene.AddJoint("j1", base, {}, Follower("/bse/arm", 1, 0));
  EXPECT_CONTAINS(ErrorOf([&] { CheckJointDependency(scene, missing); }),
                  "arm.yaml:7:13: joint '/base/j1': master '/bse/arm' matches no object");
  const ObjectId not_joint = scene.AddJoint("j2", base, {}, Follower("/base", 1, 0));
  EXPECT_EQ(ErrorOf([&] { CheckJointDependency(scene, not_joint); }),
            "arm.yaml:7:13: joint '/base/j2': master '/base' is a dummy, not a joint");
  const ObjectId self = scene.AddJoint("j3", base, {}, Follower("/base/j3", 1, 0));
  EXPECT_EQ(ErrorOf([&] { CheckJointDependency(scene, self); }),
            "arm.yaml:7:13: joint '/base/j3' cannot depend on itself");
  // An independent joint has nothing to check.
  EXPECT_NO_THROW(CheckJointDependency(scene, scene.AddJoint("free", base, {}, {})));
  // Applying refuses a broken dependency the same way.
  Scene one;
  one.AddJoint("j", {}, {}, Follower("/nothing", 1, 0));
  DependentJoints dependents;
  EXPECT_CONTAINS(ErrorOf([&] { dependents.Apply(&one, false); }), "matches no object");
}

TEST(DependentJointsTest, ACycleIsAnErrorNamingItsJoints) {
  Scene scene;
  const ObjectId a = scene.AddJoint("a", {}, {}, Follower("/b", 1, 0, "w.yaml:3:5"));
  scene.AddJoint("b", {}, {}, Follower("/c", 1, 0, "w.yaml:4:5"));
  scene.AddJoint("c", {}, {}, Follower("/a", 1, 0, "w.yaml:5:5"));
  EXPECT_EQ(ErrorOf([&] { CheckJointDependency(scene, a); }),
            "w.yaml:3:5: dependent joints form a cycle: '/a' -> '/b' -> '/c' -> '/a' "
            "(a joint cannot follow itself through its masters)");
  // A joint that leads into the cycle is not reported itself...
  const ObjectId d = scene.AddJoint("d", {}, {}, Follower("/a", 1, 0));
  EXPECT_NO_THROW(CheckJointDependency(scene, d));
  // ...but the step refuses to resolve the cycle.
  DependentJoints dependents;
  EXPECT_CONTAINS(ErrorOf([&] { dependents.Apply(&scene, false); }), "form a cycle");
}

}  // namespace
}  // namespace swarmsim
