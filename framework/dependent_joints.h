// Dependent joints (V-REP's dependent mode, URDF's mimic): a joint with a
// JointDependency takes q = offset + factor * q_master every step, masters
// first, so chains (A follows B follows C) resolve in one pass.
#pragma once

#include <cstdint>
#include <vector>

#include "framework/handle.h"

namespace swarmsim {

class Scene;

// The slot of the joint at `slot`'s master; throws Error naming the
// dependency's file:line:column when the path matches no joint.
uint32_t JointMasterSlot(const Scene& scene, uint32_t slot);

// Load check of joint `id`'s dependency: its master is a joint and following
// masters from it never comes back (a cycle is an error naming its joints).
void CheckJointDependency(const Scene& scene, ObjectId id);

// The world's dependent joints in dependency order, found again whenever the
// scene's structure changes.
class DependentJoints {
 public:
  // Non-simulated dependent joints take the formula as position and
  // factor * the master's velocity as velocity; simulated ones (a dynamics
  // backend moves them) take it as their target position when
  // `targets` is true. Returns whether there are any.
  bool Apply(Scene* scene, bool targets);

 private:
  struct Link {
    uint32_t row;
    uint32_t master_row;
  };
  void Refresh(const Scene& scene);
  uint64_t version_ = ~uint64_t{0};
  std::vector<Link> links_;  // masters before the joints that follow them
};

}  // namespace swarmsim
