// The joint type (framework/types/joint_type.cc): the keys a model file
// gives a joint, the mistakes it refuses at their file:line:column, and how
// a joint scales with its model.
#include <gtest/gtest.h>

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

JointData Read(const FakeReader& reader) {
  JointData joint;
  kJointType.read(kJointType, reader, &joint);
  return joint;
}

TEST(JointTypeTest, WithoutKeysAJointIsAVelocityDrivenRevoluteJoint) {
  const JointData j = Read(FakeReader{});
  EXPECT_EQ(j.type, JointType::kRevolute);
  EXPECT_EQ(j.mode, JointMode::kVelocity);
  EXPECT_EQ(j.max_force, 10);
  EXPECT_EQ(j.max_velocity, 10);
  EXPECT_EQ(j.position, 0);
  EXPECT_TRUE(std::isinf(j.min_position) && j.min_position < 0);
  EXPECT_TRUE(std::isinf(j.max_position) && j.max_position > 0);
  EXPECT_EQ(j.depends, nullptr);
  EXPECT_FALSE(j.ik_frozen);
  // The documented defaults are those values.
  for (const ObjectKey& key : kJointType.keys) {
    const std::string name = key.name;
    if (name == "joint") {
      EXPECT_STREQ(key.default_text, "revolute");
    } else if (name == "mode") {
      EXPECT_STREQ(key.default_text, "velocity");
    } else if (name == "max_force" || name == "max_velocity") {
      EXPECT_STREQ(key.default_text, "10");
    }
  }
}

TEST(JointTypeTest, EveryKeyReachesTheRow) {
  const JointData j = Read(FakeReader{{"joint", std::string("prismatic")},
                                      {"mode", std::string("position")},
                                      {"max_force", 40.0},
                                      {"max_velocity", 0.5},
                                      {"target_velocity", -1.0},
                                      {"target_position", 0.2},
                                      {"initial_position", 0.1},
                                      {"target_force", 3.0},
                                      {"damping", 0.7},
                                      {"limits", std::vector<double>{-0.3, 0.4}},
                                      {"ik", std::string("frozen")}});
  EXPECT_EQ(j.type, JointType::kPrismatic);
  EXPECT_EQ(j.mode, JointMode::kPosition);
  EXPECT_EQ(j.max_force, 40);
  EXPECT_EQ(j.max_velocity, 0.5);
  EXPECT_EQ(j.target_velocity, -1);
  EXPECT_EQ(j.target_position, 0.2);
  EXPECT_EQ(j.position, 0.1);  // initial_position is where the joint starts
  EXPECT_EQ(j.target_force, 3);
  EXPECT_EQ(j.damping, 0.7);
  EXPECT_EQ(j.min_position, -0.3);
  EXPECT_EQ(j.max_position, 0.4);
  EXPECT_TRUE(j.ik_frozen);
  const std::pair<const char*, JointType> kinds[] = {{"revolute", JointType::kRevolute},
                                                     {"spherical", JointType::kSpherical},
                                                     {"fixed", JointType::kFixed}};
  for (const auto& [name, type] : kinds)
    EXPECT_EQ(Read(FakeReader{{"joint", std::string(name)}}).type, type) << name;
  const std::pair<const char*, JointMode> modes[] = {{"passive", JointMode::kPassive},
                                                     {"velocity", JointMode::kVelocity},
                                                     {"force", JointMode::kForce}};
  for (const auto& [name, mode] : modes)
    EXPECT_EQ(Read(FakeReader{{"mode", std::string(name)}}).mode, mode) << name;
}

TEST(JointTypeTest, AScrewJointNeedsAFiniteNonzeroPitchAndOnlyItHasOne) {
  const JointData screw = Read(FakeReader{{"joint", std::string("screw")}, {"pitch", 0.01}});
  EXPECT_EQ(screw.type, JointType::kScrew);
  EXPECT_EQ(screw.pitch, 0.01);
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"joint", std::string("screw")}});
            }),
            "model.yaml:2:1: a screw joint needs 'pitch' (m of travel per rad, nonzero)");
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"joint", std::string("screw")}, {"pitch", 0.0}});
            }),
            "model.yaml:3:3: 'pitch' must be a finite, nonzero number of m per rad");
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"pitch", 0.01}});
            }),
            "model.yaml:2:1: 'pitch' is for screw joints (joint: screw)");
}

TEST(JointTypeTest, ADependentJointNamesItsMasterByPath) {
  const JointData j =
      Read(FakeReader{{"master", std::string(":/leftWheel")}, {"factor", -1.0}, {"offset", 0.25}});
  ASSERT_NE(j.depends, nullptr);
  EXPECT_EQ(j.depends->master, ":/leftWheel");
  EXPECT_EQ(j.depends->factor, -1);
  EXPECT_EQ(j.depends->offset, 0.25);
  EXPECT_EQ(j.depends->where, "model.yaml:2:3");  // errors about the master point here
  const JointData plain = Read(FakeReader{{"master", std::string("/base/j")}});
  EXPECT_EQ(plain.depends->factor, 1);
  EXPECT_EQ(plain.depends->offset, 0);
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"master", std::string("leftWheel")}});
            }),
            "model.yaml:2:3: 'leftWheel' is not a joint path: start with '/' (absolute), ':' "
            "(this model) or './' (below this joint)");
  for (const char* key : {"factor", "offset"})
    EXPECT_EQ(ErrorOf([&] {
                Read(FakeReader{{key, 2.0}});
              }),
              std::string("model.yaml:2:1: '") + key + "' is for dependent joints: add 'master'");
}

TEST(JointTypeTest, LimitsMustBeOrderedAndForcesPositive) {
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"limits", std::vector<double>{1, -1}}});
            }),
            "model.yaml:2:3: 'limits' must be [min, max] with min <= max");
  const JointData pinned = Read(FakeReader{{"limits", std::vector<double>{0.5, 0.5}}});
  EXPECT_EQ(pinned.min_position, 0.5);
  EXPECT_EQ(pinned.max_position, 0.5);
  EXPECT_CONTAINS(ErrorOf([] { Read(FakeReader{{"max_force", 0.0}}); }), "a positive number");
  EXPECT_CONTAINS(ErrorOf([] { Read(FakeReader{{"damping", -1.0}}); }), "a non-negative number");
  EXPECT_CONTAINS(ErrorOf([] {
                    Read(FakeReader{{"joint", std::string("hinge")}});
                  }),
                  "not 'hinge'");
}

// A revolute joint's torques scale with s^4 and its angles not at all; a
// screw's pitch and a prismatic follower's offset are lengths.
TEST(JointTypeTest, ScalingKeepsAnglesAndScalesLengthsForcesAndDamping) {
  Scene scene;
  const ObjectId root = scene.AddDummy("bot", {}, {});
  JointData hinge;
  hinge.position = 0.5;
  hinge.max_force = 2;
  hinge.target_force = 1;
  hinge.damping = 0.1;
  const ObjectId h = scene.AddJoint("hinge", root, {}, hinge);
  JointData screw;
  screw.type = JointType::kScrew;
  screw.pitch = 0.01;
  const ObjectId s = scene.AddJoint("screw", root, {}, screw);
  JointData slide;
  slide.type = JointType::kPrismatic;
  slide.damping = 0.3;
  slide.target_force = 5;
  auto dependency = std::make_shared<JointDependency>();
  dependency->master = "/bot/hinge";
  dependency->factor = 0.2;
  dependency->offset = 0.05;
  slide.depends = dependency;
  const ObjectId p = scene.AddJoint("slide", root, {}, slide);
  JointData turn;
  turn.depends = dependency;
  const ObjectId t = scene.AddJoint("turn", root, {}, turn);

  scene.ScaleSubtree(root, 2);
  EXPECT_EQ(scene.joint(h).position, 0.5);
  EXPECT_DOUBLE_EQ(scene.joint(h).max_force, 32);
  EXPECT_DOUBLE_EQ(scene.joint(h).target_force, 16);
  EXPECT_DOUBLE_EQ(scene.joint(h).damping, 1.6);
  EXPECT_DOUBLE_EQ(scene.joint(s).pitch, 0.02);
  EXPECT_DOUBLE_EQ(scene.joint(p).damping, 1.2);  // N s/m: s^2
  EXPECT_DOUBLE_EQ(scene.joint(p).target_force, 40);
  EXPECT_DOUBLE_EQ(scene.joint(p).depends->offset, 0.1);
  EXPECT_EQ(scene.joint(p).depends->factor, 0.2);
  EXPECT_EQ(scene.joint(t).depends->offset, 0.05);  // radians stay
  // The shared dependency itself is untouched (another copy may use it).
  EXPECT_EQ(dependency->offset, 0.05);
}

}  // namespace
}  // namespace swarmsim
