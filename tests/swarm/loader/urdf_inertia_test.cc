// The mass of URDF bodies (swarm/loader/urdf_inertia.h): parts combined
// about their common centre of mass (parallel-axis theorem), rotated into
// the body's frame; inertias no rigid body has are recognised and balanced
// as MuJoCo's balanceinertia does. Expected values are worked out by hand
// in the comments.
#include "swarm/loader/urdf_inertia.h"

#include <gtest/gtest.h>

#include <cmath>

namespace swarmsim::loader {
namespace {

void ExpectInertia(const Inertia& got, const Inertia& want, double tolerance = 1e-12) {
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(got[k], want[k], tolerance) << "component " << k;
}

TEST(UrdfInertiaTest, TwoPointMassesMakeARodAboutTheirMidpoint) {
  // 1 kg at x = +-0.5 m: centre 0; Iyy = Izz = 2 x 1 x 0.5^2 = 0.5, Ixx = 0.
  MassProperties body;
  AddMass({1, {0.5, 0, 0}, {}}, &body);
  AddMass({1, {-0.5, 0, 0}, {}}, &body);
  EXPECT_EQ(body.mass, 2);
  EXPECT_NEAR(body.center.Norm(), 0, 1e-15);
  ExpectInertia(body.inertia, {0, 0.5, 0.5, 0, 0, 0});
  // A rod has no inertia about its own axis: no rigid body's (not positive definite).
  EXPECT_FALSE(InertiaIsPhysical(body.inertia));
}

TEST(UrdfInertiaTest, OffsetPartsCombineAboutTheirCommonCentre) {
  // 1 kg at (0, 0, 0.1), I = 0.001 E; 3 kg at (0.2, 0, 0), I = diag(0.02,
  // 0.01, 0.03). Centre (0.15, 0, 0.025). Offsets d1 = (-0.15, 0, 0.075),
  // d2 = (0.05, 0, -0.025); m (|d|^2 E - d d^T):
  //   part 1: xx 0.005625, yy 0.028125, zz 0.0225, xz +0.01125
  //   part 2: xx 0.001875, yy 0.009375, zz 0.0075, xz +0.00375
  MassProperties body;
  AddMass({1, {0, 0, 0.1}, {0.001, 0.001, 0.001, 0, 0, 0}}, &body);
  AddMass({3, {0.2, 0, 0}, {0.02, 0.01, 0.03, 0, 0, 0}}, &body);
  EXPECT_EQ(body.mass, 4);
  EXPECT_NEAR((body.center - Vec3{0.15, 0, 0.025}).Norm(), 0, 1e-15);
  ExpectInertia(body.inertia, {0.0285, 0.0485, 0.061, 0, 0.015, 0});
  EXPECT_TRUE(InertiaIsPhysical(body.inertia));
}

TEST(UrdfInertiaTest, APartMovesAndTurnsIntoTheBodysFrame) {
  // diag(0.01, 0.02, 0.03) at (1, 0, 0) in A; A turned 90 degrees about z
  // and moved by (0, 0, 2) in B: centre (0, 1, 2), x and y swapped.
  const MassProperties part{2, {1, 0, 0}, {0.01, 0.02, 0.03, 0, 0, 0}};
  const MassProperties in_b =
      Transformed(part, Pose{{0, 0, 2}, Quat::FromAxisAngle({0, 0, 1}, M_PI / 2)});
  EXPECT_EQ(in_b.mass, 2);
  EXPECT_NEAR((in_b.center - Vec3{0, 1, 2}).Norm(), 0, 1e-15);
  ExpectInertia(in_b.inertia, {0.02, 0.01, 0.03, 0, 0, 0});
  // 45 degrees about z: Ixx' = Iyy' = (0.01 + 0.02) / 2, Ixy' = (0.01 - 0.02) / 2 ... sign:
  // R diag(a, b) R^T with c = s = 1/sqrt(2): xy = c s (a - b) = -0.005.
  const MassProperties turned =
      Transformed(part, Pose{{}, Quat::FromAxisAngle({0, 0, 1}, M_PI / 4)});
  ExpectInertia(turned.inertia, {0.015, 0.015, 0.03, -0.005, 0, 0});
}

TEST(UrdfInertiaTest, PrincipalMomentsAreTheEigenvalues) {
  const MassProperties part{1, {}, {0.3, 0.1, 0.25, 0, 0, 0}};
  const MassProperties turned = Transformed(part, Pose{{}, Quat::FromRollPitchYaw(0.3, -1.1, 2.0)});
  const auto moments = PrincipalMoments(turned.inertia);
  EXPECT_NEAR(moments[0], 0.1, 1e-14);
  EXPECT_NEAR(moments[1], 0.25, 1e-14);
  EXPECT_NEAR(moments[2], 0.3, 1e-14);
}

TEST(UrdfInertiaTest, PublishedInertiasNoBodyHasAreRecognised) {
  // A solid: yes; ixx above iyy + izz (a CAD export): no.
  EXPECT_TRUE(InertiaIsPhysical({1, 1, 1, 0, 0, 0}));
  EXPECT_TRUE(InertiaIsPhysical({0.5, 0.5, 1, 0, 0, 0}));  // a flat disc: on the bound
  EXPECT_FALSE(InertiaIsPhysical({1, 0.1, 0.1, 0, 0, 0}));
  // HyQ's base_link: 1e-6 everywhere, a singular tensor (moments 0, 0, 3e-6).
  EXPECT_FALSE(InertiaIsPhysical({1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6}));
  // TIAGo's arm_1_link: positive definite, but its principal moments
  // (0.00191, 0.00846, 0.01059) break the triangle inequality.
  const Inertia arm{0.003003, 0.008613, 0.009348, 0.002396, 0.001531, 0.000588};
  const auto m = PrincipalMoments(arm);
  EXPECT_GT(m[0], 0);
  EXPECT_GT(m[2], m[0] + m[1]);
  EXPECT_FALSE(InertiaIsPhysical(arm));
  EXPECT_FALSE(InertiaIsPhysical({0, 0, 0, 0, 0, 0}));
  EXPECT_FALSE(InertiaIsPhysical({NAN, 1, 1, 0, 0, 0}));
}

TEST(UrdfInertiaTest, BalancingKeepsTheMeanPrincipalMoment) {
  // MuJoCo's balanceinertia: each principal moment becomes their mean.
  const Inertia arm{0.003003, 0.008613, 0.009348, 0.002396, 0.001531, 0.000588};
  const double mean = (0.003003 + 0.008613 + 0.009348) / 3;
  const Inertia balanced = BalancedInertia(arm);
  ExpectInertia(balanced, {mean, mean, mean, 0, 0, 0});
  EXPECT_TRUE(InertiaIsPhysical(balanced));
  const auto m = PrincipalMoments(arm);
  EXPECT_NEAR((m[0] + m[1] + m[2]) / 3, mean, 1e-15);
}

}  // namespace
}  // namespace swarmsim::loader
