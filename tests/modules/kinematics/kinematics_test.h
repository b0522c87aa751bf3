// Shared by the kinematics tests and bench: the UR5 built in a scene from its
// published Denavit-Hartenberg parameters, and an independent DH product.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "framework/scene.h"

namespace swarmsim::kinematics::testing {

// Universal Robots UR5, standard DH (Universal Robots' published table), m and rad.
inline constexpr std::array<double, 6> kUr5D = {0.089159, 0, 0, 0.10915, 0.09465, 0.0823};
inline constexpr std::array<double, 6> kUr5A = {0, -0.425, -0.39225, 0, 0, 0};
inline constexpr std::array<double, 6> kUr5Alpha = {M_PI / 2, 0, 0, M_PI / 2, -M_PI / 2, 0};

struct Ur5 {
  ObjectId base, tip;
  std::vector<ObjectId> joints;
};

// base (dummy) -> J1 -> link1 (dummy, Tz(d) Tx(a) Rx(alpha)) -> J2 -> ... -> link6 -> tip.
inline Ur5 AddUr5(Scene* scene, const Pose& X_WBase = {}) {
  Ur5 arm;
  arm.base = scene->AddDummy("ur5", {}, X_WBase);
  ObjectId parent = arm.base;
  for (int i = 0; i < 6; ++i) {
    JointData j;
    j.settings.Edit().type = JointType::kRevolute;
    j.settings.Edit().mode = JointMode::kPassive;
    const ObjectId joint = scene->AddJoint("joint" + std::to_string(i + 1), parent, {}, j);
    arm.joints.push_back(joint);
    parent =
        scene->AddDummy("link" + std::to_string(i + 1), joint,
                        {{kUr5A[i], 0, kUr5D[i]}, Quat::FromAxisAngle({1, 0, 0}, kUr5Alpha[i])});
  }
  arm.tip = scene->AddDummy("tip", parent, {});
  return arm;
}

using Matrix4 = std::array<std::array<double, 4>, 4>;

inline Matrix4 Multiply(const Matrix4& a, const Matrix4& b) {
  Matrix4 c{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) c[i][j] += a[i][k] * b[k][j];
  return c;
}

// Standard DH: T = Rz(theta) Tz(d) Tx(a) Rx(alpha), written out as a matrix.
inline Matrix4 DhTransform(double theta, double d, double a, double alpha) {
  const double ct = std::cos(theta), st = std::sin(theta), ca = std::cos(alpha),
               sa = std::sin(alpha);
  return {{{ct, -st * ca, st * sa, a * ct},
           {st, ct * ca, -ct * sa, a * st},
           {0, sa, ca, d},
           {0, 0, 0, 1}}};
}

inline Matrix4 Ur5ForwardKinematics(const std::array<double, 6>& q) {
  Matrix4 T{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
  for (int i = 0; i < 6; ++i) T = Multiply(T, DhTransform(q[i], kUr5D[i], kUr5A[i], kUr5Alpha[i]));
  return T;
}

}  // namespace swarmsim::kinematics::testing
