// Forward kinematics (chain.h) against closed forms and the UR5's published
// DH kinematics.
#include "modules/kinematics/chain.h"

#include <gtest/gtest.h>

#include <random>

#include "framework/error.h"
#include "modules/kinematics/ik_solver.h"
#include "tests/modules/kinematics/kinematics_test.h"

namespace swarmsim::kinematics {
namespace {

using testing::AddUr5;
using testing::Ur5ForwardKinematics;

JointData Revolute(double min = -INFINITY, double max = INFINITY) {
  JointData j;
  j.settings.Edit().type = JointType::kRevolute;
  j.settings.Edit().mode = JointMode::kPassive;
  j.settings.Edit().min_position = min;
  j.settings.Edit().max_position = max;
  return j;
}

// Rotation matrix entry (row i, column j) of q.
double R(const Quat& q, int i, int j) {
  const Vec3 col = q.Rotate({j == 0 ? 1.0 : 0, j == 1 ? 1.0 : 0, j == 2 ? 1.0 : 0});
  return i == 0 ? col.x : i == 1 ? col.y : col.z;
}

TEST(ForwardKinematics, TwoLinkPlanarArmMatchesTheClosedForm) {
  Scene scene;
  const double l1 = 0.7, l2 = 0.4;
  const ObjectId j1 = scene.AddJoint("j1", {}, {}, Revolute());
  const ObjectId j2 = scene.AddJoint("j2", j1, {{l1, 0, 0}, {}}, Revolute());
  const ObjectId tip = scene.AddDummy("tip", j2, {{l2, 0, 0}, {}});
  const Chain chain = Chain::FromScene(scene, {}, tip);
  ASSERT_EQ(chain.dof(), 2);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  for (int trial = 0; trial < 100; ++trial) {
    const double q1 = angle(rng), q2 = angle(rng);
    scene.mutable_joint(j1).position = q1;
    scene.mutable_joint(j2).position = q2;
    scene.UpdateWorldPoses();
    const Vec3 expected{l1 * std::cos(q1) + l2 * std::cos(q1 + q2),
                        l1 * std::sin(q1) + l2 * std::sin(q1 + q2), 0};
    const Vec3 p_scene = scene.world_pose(tip).p;
    const double q[2] = {q1, q2};
    const Pose X_chain = chain.CalcTipPose(q);
    EXPECT_NEAR((p_scene - expected).Norm(), 0, 1e-12);
    EXPECT_NEAR((X_chain.p - expected).Norm(), 0, 1e-12);
    EXPECT_NEAR(std::remainder(X_chain.q.Yaw() - (q1 + q2), 2 * M_PI), 0, 1e-12);
  }
}

TEST(ForwardKinematics, Ur5MatchesItsPublishedDhKinematics) {
  Scene scene;
  const auto arm = AddUr5(&scene);
  const Chain chain = Chain::FromScene(scene, arm.base, arm.tip);
  ASSERT_EQ(chain.dof(), 6);
  // The zero configuration: the tool at (a2 + a3, -(d4 + d6), d1 - d5).
  {
    const double q[6] = {};
    const Vec3 p = chain.CalcTipPose(q).p;
    EXPECT_NEAR(p.x, -0.81725, 1e-12);
    EXPECT_NEAR(p.y, -0.19145, 1e-12);
    EXPECT_NEAR(p.z, -0.005491, 1e-12);
  }
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> angle(-2 * M_PI, 2 * M_PI);
  for (int trial = 0; trial < 200; ++trial) {
    std::array<double, 6> q;
    for (int i = 0; i < 6; ++i) {
      q[i] = angle(rng);
      scene.mutable_joint(arm.joints[i]).position = q[i];
    }
    scene.UpdateWorldPoses();
    const auto T = Ur5ForwardKinematics(q);
    for (const Pose& X : {scene.world_pose(arm.tip), chain.CalcTipPose(q)}) {
      EXPECT_NEAR(X.p.x, T[0][3], 1e-9);
      EXPECT_NEAR(X.p.y, T[1][3], 1e-9);
      EXPECT_NEAR(X.p.z, T[2][3], 1e-9);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(R(X.q, i, j), T[i][j], 1e-9);
    }
  }
}

TEST(ForwardKinematics, BaseMustBeAnAncestorOfTheTip) {
  Scene scene;
  const auto arm = AddUr5(&scene);
  const ObjectId other = scene.AddDummy("other", {}, {});
  EXPECT_THROW(Chain::FromScene(scene, other, arm.tip), Error);
}

}  // namespace
}  // namespace swarmsim::kinematics
