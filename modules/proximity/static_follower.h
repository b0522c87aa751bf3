// The static shapes of the proximity backend's static index, followed from
// step to step (internal to modules/proximity): one that a script, a path or
// a joint moved is moving from then on (the backend places it with the
// robots and leaves it out of the index), and shapes added, removed or
// rescaled have the index built again. Holds slots and poses only.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "framework/math.h"
#include "modules/proximity/ray_cast.h"

namespace swarmsim {
class Scene;
}  // namespace swarmsim

namespace swarmsim::proximity {

class StaticIndex;

class StaticFollower {
 public:
  // After `index` was built: the shapes it holds, as they are now.
  void Indexed(const Scene& scene, const StaticIndex& index);
  // Once a step: true when the index must be built again (leaving out moved()).
  bool Follow(const Scene& scene);
  // The moved shapes where they are now, for LineBlocked.
  void PlaceMoved(const Scene& scene);

  // Static shapes that moved since they were indexed (ascending slots).
  std::span<const uint32_t> moved() const { return moved_; }
  bool IsMoved(uint32_t slot) const {
    return !moved_.empty() && std::binary_search(moved_.begin(), moved_.end(), slot);
  }
  // Does a moved static shape cross the ray (p_W, unit d_W, length)?
  bool LineBlocked(const Vec3& p_W, const Vec3& d_W, double length) const;

 private:
  std::vector<uint32_t> slots_;      // as indexed: ascending
  std::vector<Pose> poses_;          // their world poses then
  std::vector<Vec3> sizes_;          // and sizes
  uint64_t version_ = ~uint64_t{0};  // the scene structure they were listed at
  std::vector<uint32_t> moved_;
  std::vector<PlacedShape> placed_;  // moved_, placed by PlaceMoved
};

}  // namespace swarmsim::proximity
