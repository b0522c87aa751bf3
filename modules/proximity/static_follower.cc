#include "modules/proximity/static_follower.h"

#include <iterator>
#include <utility>

#include "framework/scene.h"
#include "modules/proximity/static_index.h"

namespace swarmsim::proximity {

namespace {

// A shape of no robot that is not dynamic (static_index.h's static shape).
bool IsStaticShape(const Scene& scene, uint32_t slot, const ShapeData& shape) {
  return scene.alive_at(slot) && scene.instance_of_at(slot) < 0 && !shape.dynamic;
}

}  // namespace

void StaticFollower::Indexed(const Scene& scene, const StaticIndex& index) {
  slots_.clear();
  poses_.clear();
  sizes_.clear();
  for (const PlacedShape& shape : index.shapes()) {
    if (shape.id.IsNull()) continue;  // a voxel of the environment map
    const uint32_t slot = shape.id.index();
    slots_.push_back(slot);
    poses_.push_back(scene.world_pose_at(slot));
    sizes_.push_back(scene.shapes()[scene.row_at(slot)].size);
  }
  version_ = scene.structure_version();
}

bool StaticFollower::Follow(const Scene& scene) {
  if (version_ != scene.structure_version()) {
    // Objects added or removed: the static shapes now, those known to move
    // staying with the moving ones.
    std::vector<uint32_t> now;
    const auto shapes = scene.shapes();
    const auto owners = scene.shape_owners();
    for (size_t r = 0; r < shapes.size(); ++r)
      if (IsStaticShape(scene, owners[r], shapes[r])) now.push_back(owners[r]);
    std::sort(now.begin(), now.end());
    std::vector<uint32_t> moved, fixed;
    std::set_intersection(moved_.begin(), moved_.end(), now.begin(), now.end(),
                          std::back_inserter(moved));
    std::set_difference(now.begin(), now.end(), moved.begin(), moved.end(),
                        std::back_inserter(fixed));
    moved_ = std::move(moved);
    version_ = scene.structure_version();
    if (fixed != slots_) return true;
    // Rescaled (sim.scaleObject): indexed at its new size.
    for (size_t i = 0; i < slots_.size(); ++i)
      if (!(shapes[scene.row_at(slots_[i])].size == sizes_[i])) return true;
  }
  // Moved since they were indexed: moving from now on.
  const size_t known = moved_.size();
  for (size_t i = 0; i < slots_.size(); ++i)
    if (!(scene.world_pose_at(slots_[i]) == poses_[i])) moved_.push_back(slots_[i]);
  if (moved_.size() == known) return false;
  std::sort(moved_.begin(), moved_.end());
  return true;
}

void StaticFollower::PlaceMoved(const Scene& scene) {
  placed_.clear();
  for (uint32_t slot : moved_)
    placed_.push_back(PlaceShape(scene.shapes()[scene.row_at(slot)], scene.world_pose_at(slot),
                                 scene.IdAt(slot), -1));
}

bool StaticFollower::LineBlocked(const Vec3& p_W, const Vec3& d_W, double length) const {
  double t = 0;
  for (const PlacedShape& shape : placed_)
    if (RayCast(shape, p_W, d_W, length, &t)) return true;
  return false;
}

}  // namespace swarmsim::proximity
