// The static environment of the proximity module: the shapes that belong to
// no robot and are not dynamic, and the voxels of the scene's environment
// map (framework/environment.h, as boxes of no object), as they are at
// Build() time, indexed in an OctoMap octree. (The backend builds it again
// when static shapes come or go, and leaves out those that moved: it places
// them with the moving shapes.)
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
// The octree's keys (16 bits per axis) span 65,536 voxels: it is centred
// on the origin, or moved to hold the static environment where that lies
// elsewhere; shapes beyond its keys (a static environment wider than
// 65,536 voxels: 3,276.8 m at the default 0.05 m) are kept apart and
// tested one by one, so any finite coordinate works, only slower.
//
// A coarse occupancy map, built once from the octree's occupied leaves,
// answers "may anything static be in this box?" with a few bit tests: it
// lets a robot far from every wall skip its rays without an octree descent,
// and lets a ray skip the octree where it crosses only empty cells.
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
struct EnvironmentMap;
}  // namespace swarmsim

namespace swarmsim::proximity {

class StaticIndex {
 public:
  StaticIndex();
  ~StaticIndex();
  StaticIndex(const StaticIndex&) = delete;
  StaticIndex& operator=(const StaticIndex&) = delete;

  // Indexes the static shapes of `scene` at `resolution` (m), but those at
  // the slots `left_out` (ascending: static shapes that move, which the
  // backend places with the moving ones). Throws swarmsim::Error for a bad
  // resolution, a static shape whose pose or size is not finite, or an
  // environment too large for the octree at it.
  void Build(const Scene& scene, double resolution, std::span<const uint32_t> left_out = {});

  bool empty() const { return shapes_.empty(); }
  std::span<const PlacedShape> shapes() const { return shapes_; }
  // Nodes in the (pruned) octree, for memory reports.
  size_t octree_node_count() const;

  // May any occupied voxel meet the world box [lo, hi]? Cheap descent of the
  // octree: most sensors of a swarm are far from every wall.
  bool AnyOccupied(const Vec3& lo, const Vec3& hi) const;
  // Conservative and cheaper still: false only if AnyOccupied(lo', hi') is
  // false for every box [lo', hi'] inside [lo, hi]. Reads the coarse map only.
  bool MayBeOccupied(const Vec3& lo, const Vec3& hi) const;
  // Is the coarse map at voxel resolution, so that MayBeOccupied is
  // AnyOccupied (for static geometry within about 1,400 x 1,400 x 16 voxels)?
  bool coarse_map_is_exact() const {
    return coarse_shift_[0] == 0 && coarse_shift_[1] == 0 && coarse_shift_[2] == 0;
  }

  // The static shapes that may meet the world box [lo, hi] (a superset:
  // those of the octree buckets it reaches), as indices into shapes(),
  // ascending (*out cleared first). For volume sensors.
  void ShapesInBox(const Vec3& lo, const Vec3& hi, std::vector<uint32_t>* out) const;

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
  // key_offset_ for the static shapes (bounds lo, hi) and the map.
  void ChooseKeyOffsets(const EnvironmentMap* map, const std::vector<Vec3>& lo,
                        const std::vector<Vec3>& hi, double margin);
  // Voxel key of a coordinate along `axis`, unclamped (may fall outside 0..65535).
  double RawKey(double coordinate, int axis) const;
  // The same, clamped to +-1e9 (cheaper; equal to RawKey between). Not NaN.
  int ClampedKey(double coordinate, int axis) const;
  // Does the box [lo, hi] meet the bounds of a shape beyond the octree?
  bool FarOverlaps(const Vec3& lo, const Vec3& hi) const;
  // CastRay and ShapesInBox over the octree's shapes only.
  bool CastRayInOctree(const Vec3& p_W, const Vec3& d_W, double max_t,
                       std::span<const ObjectId> skip, double* t, uint32_t* shape) const;
  void ShapesInBoxInOctree(const Vec3& lo, const Vec3& hi, std::vector<uint32_t>* out) const;
  // Builds coarse_ from the octree (end of Build).
  void BuildCoarseMap();
  // Index of coarse column (x, y) in coarse_: the 64 columns of a block are
  // contiguous (two cache lines).
  size_t ColumnIndex(int x, int y) const;
  // Does the coarse cell of voxel `key` (within occupied_keys_) hold part of
  // an occupied leaf?
  bool CoarseCellOccupied(const int key[3]) const;
  // Marks the coarse cells of the occupied leaves under `node` (key cube
  // `origin`, edge `size`), as AnyOccupiedIn would find them.
  void MarkCoarse(const octomap::OcTreeNode* node, const int origin[3], int size);

  std::unique_ptr<octomap::OcTree> tree_;
  double resolution_ = 0.05;
  double inv_resolution_ = 20;
  int key_offset_[3] = {32768, 32768, 32768};  // the key of coordinate 0 per axis
  // Shapes beyond the octree's keys (indices into shapes_, ascending) and
  // their world bounds (far shapes).
  std::vector<uint32_t> far_;
  std::vector<Vec3> far_lo_, far_hi_;
  std::vector<PlacedShape> shapes_;  // the static shapes (static shapes)
  // Meshes of the static shapes, kept alive while shapes_ points at them (static meshes).
  std::vector<std::shared_ptr<const TriangleMesh>> meshes_;
  // Bucket key -> [begin, end) in bucket_shapes_.
  std::unordered_map<uint64_t, std::pair<uint32_t, uint32_t>> buckets_;
  std::vector<uint32_t> bucket_shapes_;  // shape indices, ascending per bucket
  KeyBox occupied_keys_{};               // key bounds of the occupied voxels
  Vec3 occupied_lo_, occupied_hi_;       // the same, in metres
  // Coarse occupancy map. A coarse cell holds the voxel keys k with
  // (k - occupied_keys_.lo) >> coarse_shift_ equal per axis; a bit is set if
  // an occupied leaf (voxel or pruned block) meets the cell. One 16-bit mask
  // over z per (x, y) column, grouped in blocks of 8 x 8 columns (see
  // ColumnIndex); and per block the OR of its masks, small enough to stay
  // in cache.
  std::vector<uint16_t> coarse_;  // (block_count_[0] x block_count_[1] x 64)
  std::vector<uint16_t> blocks_;  // (block_count_[0] x block_count_[1])
  int coarse_shift_[3] = {0, 0, 0};
  int coarse_size_[3] = {0, 0, 0};  // cells per axis
  int block_count_[2] = {0, 0};
};

}  // namespace swarmsim::proximity
