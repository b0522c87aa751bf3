// The scene shapes a planar engine (box2d, planar) built into fixed
// obstacles, with the world pose each had then. A static shape is fixed in
// the engine but not in the scene: a script (sim.setObjectPose), a path
// follower or a joint outside any robot may move it. Moved() tells the
// engine so, and it places those obstacles again on that step, so that
// robots meet the shape where it is now.
// Engine-neutral (slots and poses).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "framework/scene.h"

namespace swarmsim::dynamics {

class ObstaclePoses {
 public:
  void Clear() {
    slots_.clear();
    poses_.clear();
  }
  void Add(uint32_t slot, const Pose& X_WS) {
    slots_.push_back(slot);
    poses_.push_back(X_WS);
  }
  // Has any of them a world pose other than the one it was built at? (Bit
  // for bit: a NaN pose counts as moved, and the rebuild refuses it.)
  bool Moved(const Scene& scene) const {
    for (size_t i = 0; i < slots_.size(); ++i)
      if (!(scene.world_pose_at(slots_[i]) == poses_[i])) return true;
    return false;
  }
  // The slots of those that moved (ascending as added), into *out (cleared).
  void MovedSlots(const Scene& scene, std::vector<uint32_t>* out) const {
    out->clear();
    for (size_t i = 0; i < slots_.size(); ++i)
      if (!(scene.world_pose_at(slots_[i]) == poses_[i])) out->push_back(slots_[i]);
  }
  bool empty() const { return slots_.empty(); }
  std::span<const uint32_t> slots() const { return slots_; }
  // Takes their poses as they are now (an engine that moved its obstacles).
  void Refresh(const Scene& scene) {
    for (size_t i = 0; i < slots_.size(); ++i) poses_[i] = scene.world_pose_at(slots_[i]);
  }

 private:
  std::vector<uint32_t> slots_;
  std::vector<Pose> poses_;
};

}  // namespace swarmsim::dynamics
