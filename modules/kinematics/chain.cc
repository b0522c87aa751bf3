#include "modules/kinematics/chain.h"

#include <algorithm>
#include <string>

#include "framework/error.h"

namespace swarmsim::kinematics {

Pose ChainJoint::Motion(double q, const Quat& rotation) const {
  switch (kind) {
    case ChainJointKind::kRevolute: return {{}, {std::cos(q / 2), 0, 0, std::sin(q / 2)}};
    case ChainJointKind::kPrismatic: return {{0, 0, q}, {}};
    case ChainJointKind::kScrew:
      return {{0, 0, pitch * q}, {std::cos(q / 2), 0, 0, std::sin(q / 2)}};
    case ChainJointKind::kSpherical: return {{}, rotation};
  }
  return {};
}

Chain Chain::FromScene(const Scene& scene, ObjectId base, ObjectId tip) {
  const uint32_t tip_slot = scene.SlotOf(tip, "IK tip");
  const int32_t base_slot =
      base.IsNull() ? -1 : static_cast<int32_t>(scene.SlotOf(base, "IK base"));
  // Path from the tip up to (not including) the base.
  std::vector<uint32_t> path;
  int32_t s = static_cast<int32_t>(tip_slot);
  while (s >= 0 && s != base_slot) {
    path.push_back(static_cast<uint32_t>(s));
    s = scene.parent_at(static_cast<uint32_t>(s));
  }
  if (s != base_slot)
    throw Error("'" + scene.PathOf(base) + "' is not an ancestor of '" + scene.PathOf(tip) +
                "': an IK chain runs from a base down to its tip");
  std::reverse(path.begin(), path.end());

  Chain chain;
  chain.X_WBase_ = base_slot >= 0 ? scene.ChildFrameAt(static_cast<uint32_t>(base_slot)) : Pose{};
  Pose X_acc;  // from the last moved frame to the current object
  for (uint32_t slot : path) {
    X_acc = X_acc * scene.local_pose_at(slot);
    if (scene.type_at(slot) != ObjectType::kJoint) continue;
    const JointData& j = scene.joints()[scene.row_at(slot)];
    ChainJoint c{X_acc,
                 ChainJointKind::kRevolute,
                 0,
                 j.settings->min_position,
                 j.settings->max_position,
                 j.ball,
                 slot};
    switch (j.type()) {
      case JointType::kRevolute: break;
      case JointType::kPrismatic: c.kind = ChainJointKind::kPrismatic; break;
      case JointType::kScrew:
        c.kind = ChainJointKind::kScrew;
        c.pitch = j.settings->pitch;
        break;
      case JointType::kSpherical: c.kind = ChainJointKind::kSpherical; break;
      case JointType::kFixed: X_acc = X_acc * j.Motion(); continue;
    }
    chain.joints_.push_back(c);
    X_acc = Pose{};
  }
  chain.X_after_ = X_acc;
  return chain;
}

std::vector<double> Chain::ReadPositions(const Scene& scene) const {
  std::vector<double> q;
  q.reserve(joints_.size());
  for (const ChainJoint& j : joints_) q.push_back(scene.joints()[scene.row_at(j.slot)].position);
  return q;
}

void Chain::WritePositions(std::span<const double> q, Scene* scene) const {
  for (size_t i = 0; i < joints_.size(); ++i)
    scene->joints()[scene->row_at(joints_[i].slot)].position = q[i];
}

Pose Chain::CalcTipPose(std::span<const double> q) const {
  Pose X = X_WBase_;
  for (size_t i = 0; i < joints_.size(); ++i)
    X = X * joints_[i].X_before * joints_[i].Motion(q[i], joints_[i].ball);
  return X * X_after_;
}

Pose Chain::CalcTipPose(std::span<const double> q, Pose* X_WJ) const {
  Pose X = X_WBase_;
  for (size_t i = 0; i < joints_.size(); ++i) {
    X = X * joints_[i].X_before;
    X_WJ[i] = X;  // the axis frame (motion about/along its z)
    X = X * joints_[i].Motion(q[i], joints_[i].ball);
  }
  return X * X_after_;
}

Pose Chain::CalcTipPose(std::span<const double> q, std::span<const Quat> ball, Pose* X_WJ) const {
  Pose X = X_WBase_;
  for (size_t i = 0; i < joints_.size(); ++i) {
    X = X * joints_[i].X_before;
    X_WJ[i] = X;
    X = X * joints_[i].Motion(q[i], ball[i]);
  }
  return X * X_after_;
}

}  // namespace swarmsim::kinematics
