// The static environment of the proximity module: the shapes that belong to
// no robot and are not dynamic, frozen at Build() time, indexed in an
// OctoMap octree.
//
// Every voxel a shape may overlap (conservatively) is marked occupied. Shape
// lists are kept per *bucket* of 4x4x4 voxels (a map from the bucket's key to
// the static shapes touching any of its voxels), which keeps the map 64 times
// smaller than a per-voxel one for large walls and floors while the octree
// still gives voxel-fine empty-space skipping. A ray walks the voxels it
// crosses with a 3D DDA over octree keys (no allocation), and for each
// occupied voxel tests the bucket's shapes exactly; the nearest exact hit
// wins, so distances are exact to the geometry, not to the voxel size.
//
// Internal to modules/proximity (OctoMap types stay in this module).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>
#include <vector>

#include "framework/math.h"
#include "modules/proximity/ray_cast.h"

namespace octomap {
class OcTree;
class OcTreeNode;
}  // namespace octomap

namespace swarmsim {
class Scene;
}

namespace swarmsim::proximity {

class StaticIndex {
 public:
  StaticIndex();
  ~StaticIndex();
  StaticIndex(const StaticIndex&) = delete;
  StaticIndex& operator=(const StaticIndex&) = delete;

  // Indexes the static shapes of `scene` at `resolution` (m). Throws
  // swarmsim::Error for a bad resolution or a shape outside the octree's
  // reach (+-32768 voxels around the origin).
  void Build(const Scene& scene, double resolution);

  bool empty() const { return shapes_.empty(); }
  std::span<const PlacedShape> shapes() const { return shapes_; }
  // Nodes in the (pruned) octree, for memory reports.
  size_t octree_node_count() const;

  // May any occupied voxel meet the world box [lo, hi]? Cheap descent of the
  // octree: most sensors of a swarm are far from every wall.
  bool AnyOccupied(const Vec3& lo, const Vec3& hi) const;

  // Nearest exact hit of the ray (p_W, unit d_W, length max_t) on a static
  // shape not listed in `skip`. Sets *t and *shape (index into shapes()).
  bool CastRay(const Vec3& p_W, const Vec3& d_W, double max_t, std::span<const ObjectId> skip,
               double* t, uint32_t* shape) const;

 private:
  struct KeyBox {
    int lo[3], hi[3];  // inclusive voxel key ranges
  };
  bool AnyOccupiedIn(const octomap::OcTreeNode* node, const int origin[3], int size,
                     const KeyBox& box) const;
  // The node on the way from `node` (whose children split on key bit `bit`)
  // to voxel `key` that holds it: the voxel, a pruned occupied block, or null.
  const octomap::OcTreeNode* Descend(const octomap::OcTreeNode* node, int bit,
                                     const int key[3]) const;
  // The deepest node holding the key box [lo, hi] (or a pruned block around
  // it); *bit is the key bit its children split on. Null: the box is empty.
  const octomap::OcTreeNode* CommonAncestor(const int lo[3], const int hi[3], int* bit) const;
  // Voxel key of a coordinate, unclamped (may fall outside 0..65535).
  double RawKey(double coordinate) const;

  std::unique_ptr<octomap::OcTree> tree_;
  double resolution_ = 0.05;
  double inv_resolution_ = 20;
  std::vector<PlacedShape> shapes_;  // the static shapes (static shapes)
  // Meshes of the static shapes, kept alive while shapes_ points at them (static meshes).
  std::vector<std::shared_ptr<const TriangleMesh>> meshes_;
  // Bucket key -> [begin, end) in bucket_shapes_.
  std::unordered_map<uint64_t, std::pair<uint32_t, uint32_t>> buckets_;
  std::vector<uint32_t> bucket_shapes_;  // shape indices, ascending per bucket
  KeyBox occupied_keys_{};               // key bounds of the occupied voxels
  Vec3 occupied_lo_, occupied_hi_;       // the same, in metres
};

}  // namespace swarmsim::proximity
