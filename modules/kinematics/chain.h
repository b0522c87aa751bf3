// Kinematic chains extracted from the scene: forward kinematics for any
// serial path of the tree (a tree's branches are several chains sharing a
// prefix), fast enough to run inside an IK loop (no scene writes).
//
// A chain runs from a base object (or the world) down to a tip object. Its
// joints are the revolute, prismatic, screw and spherical joints on the
// path, in order from the base; every other object on the path (dummies,
// shapes, fixed joints) folds into the constant transform between two
// joints.
//
//   X_W(tip) = X_W(base) * X_0 * M_1 * X_1 * M_2 * ... * M_n * X_n
//
// M_i is the joint's motion (JointData::Motion()): a rotation about, or a
// translation along, its own z axis by q; both for a screw joint (pitch * q
// along z); a free rotation (`ball`) for a spherical joint.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/scene.h"

namespace swarmsim::kinematics {

enum class ChainJointKind : uint8_t { kRevolute, kPrismatic, kScrew, kSpherical };

struct ChainJoint {  // 128 bytes
  Pose X_before;     // constant transform from the previous joint's moved frame (or the base)
  ChainJointKind kind = ChainJointKind::kRevolute;
  double pitch = 0;                   // screw: m along z per rad
  double min_position, max_position;  // limits, rad or m (spherical: none)
  Quat ball;                          // spherical: its rotation at extraction
  uint32_t slot;                      // the joint's scene slot

  bool prismatic() const { return kind == ChainJointKind::kPrismatic; }
  // The motion for position q (rotation `ball` for a spherical joint).
  Pose Motion(double q, const Quat& ball) const;
};

class Chain {
 public:
  // The path from `base` (null: the world) down to `tip`. Throws
  // swarmsim::Error if `base` is not an ancestor of `tip`.
  static Chain FromScene(const Scene& scene, ObjectId base, ObjectId tip);

  // The joints on the path (a spherical joint counts once).
  int dof() const { return static_cast<int>(joints_.size()); }
  std::span<const ChainJoint> joints() const { return joints_; }
  // Current joint positions in the scene (chain order).
  std::vector<double> ReadPositions(const Scene& scene) const;
  // Writes positions to the scene's joints (JointData::position); the caller
  // refreshes world poses.
  void WritePositions(std::span<const double> q, Scene* scene) const;
  // Pose of the base in the world, as of extraction (moving bases: refresh
  // with set_X_WBase before solving).
  const Pose& X_WBase() const { return X_WBase_; }
  void set_X_WBase(const Pose& X) { X_WBase_ = X; }

  // World pose of the tip for positions q (size dof(); spherical joints at
  // their rotation of extraction).
  Pose CalcTipPose(std::span<const double> q) const;
  // Same, and the world frame of each joint before its motion (size dof()),
  // whose z axis and origin give the Jacobian columns.
  Pose CalcTipPose(std::span<const double> q, Pose* X_WJ) const;
  // Same with each spherical joint's rotation from `ball` (size dof()).
  Pose CalcTipPose(std::span<const double> q, std::span<const Quat> ball, Pose* X_WJ) const;

 private:
  Pose X_WBase_;
  std::vector<ChainJoint> joints_;
  Pose X_after_;  // last joint's moved frame (or the base) to the tip
};

}  // namespace swarmsim::kinematics
