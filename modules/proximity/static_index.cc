#include "modules/proximity/static_index.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "framework/environment.h"
#include "framework/error.h"
#include "framework/scene.h"

namespace swarmsim::proximity {
namespace {

constexpr int kKeyOffset = 32768;  // the key of coordinate 0 unless the octree is moved
constexpr int kMaxKey = 65535;
constexpr double kMaxShift =
    1e8;                          // |key offset| at most: ClampedKey's +-1e9 stays beyond every key
constexpr int kBucketShift = 2;   // a bucket is 4x4x4 voxels
constexpr int kTreeSize = 65536;  // keys per axis
constexpr int kTreeDepth = 16;
constexpr double kMaxVoxelTests = 2e8;  // guards Build against absurd resolutions
constexpr int kTestedCapacity = 16;     // shapes remembered per ray to avoid retesting
constexpr int kCoarseZCells = 16;       // bits in a column mask
constexpr int kBlockShift = 3;          // a block is 8 x 8 columns
constexpr int64_t kMaxCoarseColumns = int64_t{1} << 21;  // 4 MiB of column masks at most

uint64_t PackBucket(int bx, int by, int bz) {
  return (static_cast<uint64_t>(bx) << 32) | (static_cast<uint64_t>(by) << 16) |
         static_cast<uint64_t>(bz);
}

double Axis(const Vec3& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }

// Intersects [*t_lo, *t_hi] with the t where lo <= o + t d <= hi.
bool ClipSlab(double o, double d, double lo, double hi, double* t_lo, double* t_hi) {
  if (d == 0) return o >= lo && o <= hi;
  double t1 = (lo - o) / d, t2 = (hi - o) / d;
  if (t1 > t2) std::swap(t1, t2);
  *t_lo = std::max(*t_lo, t1);
  *t_hi = std::min(*t_hi, t2);
  return *t_lo <= *t_hi;
}

// Makes `node` and everything below it occupied: a childless node becomes
// an occupied leaf; below one with children, the missing children are
// added as occupied leaves (prune() merges them).
void FillOccupied(octomap::OcTree* tree, octomap::OcTreeNode* node, float occupied,
                  int64_t* nodes) {
  if (!tree->nodeHasChildren(node)) {
    node->setLogOdds(occupied);
    return;
  }
  for (unsigned int c = 0; c < 8; ++c) {
    if (tree->nodeChildExists(node, c)) {
      FillOccupied(tree, tree->getNodeChild(node, c), occupied, nodes);
    } else {
      ++*nodes;
      tree->createNodeChild(node, c)->setLogOdds(occupied);
    }
  }
}

// Marks the voxels of the key box [lo, hi] (inclusive) occupied below
// `node` (key cube `origin`, edge `size`) as whole cubes: a cube inside the
// box becomes one occupied leaf (what prune() would make of its voxels).
// Every childless node here is an occupied leaf (voxels and cubes are
// only ever added occupied), so one found on the way already covers its
// part; `fresh`: the node was just created (childless, not yet a leaf).
// Counts created nodes in *nodes.
void InsertKeyBox(octomap::OcTree* tree, octomap::OcTreeNode* node, const int origin[3], int size,
                  const int lo[3], const int hi[3], float occupied, bool fresh, int64_t* nodes) {
  bool inside = true;
  for (int i = 0; i < 3; ++i)
    inside = inside && origin[i] >= lo[i] && origin[i] + size - 1 <= hi[i];
  if (inside) return FillOccupied(tree, node, occupied, nodes);
  if (!fresh && !tree->nodeHasChildren(node)) return;  // inside an occupied leaf
  const int half = size / 2;
  for (unsigned int c = 0; c < 8; ++c) {
    const int child[3] = {origin[0] + ((c & 1) ? half : 0), origin[1] + ((c & 2) ? half : 0),
                          origin[2] + ((c & 4) ? half : 0)};
    bool overlaps = true;
    for (int i = 0; i < 3; ++i)
      overlaps = overlaps && child[i] <= hi[i] && child[i] + half - 1 >= lo[i];
    if (!overlaps) continue;
    const bool exists = tree->nodeChildExists(node, c);
    if (!exists) ++*nodes;
    InsertKeyBox(tree, exists ? tree->getNodeChild(node, c) : tree->createNodeChild(node, c), child,
                 half, lo, hi, occupied, !exists, nodes);
  }
}

// The environment map's boxes (framework/environment.h) as static boxes of
// no object (null id, instance -1), appended to `shapes`; the voxels their
// interiors meet marked in `tree` a box at a time (InsertKeyBox: no
// per-voxel overlap tests; a box on the octree's grid is one node), and the
// buckets they touch added to `touches`. Grows the key bounds.
void AddEnvironment(const EnvironmentMap& map, double resolution, const int key_offset[3],
                    octomap::OcTree* tree, std::vector<PlacedShape>* shapes,
                    std::vector<uint32_t>* far, std::vector<std::pair<uint64_t, uint32_t>>* touches,
                    int key_lo[3], int key_hi[3]) {
  const float occupied = tree->getClampingThresMaxLog();
  const double inv_resolution = 1 / resolution;
  const double shrink = resolution * 1e-6;  // a box's faces do not mark the voxels beyond
  constexpr int64_t kMaxNodes = 20000000;   // about 1.6 GB of octree
  int64_t nodes = 0;
  for (const EnvironmentBox& box : map.boxes) {
    const uint32_t s = static_cast<uint32_t>(shapes->size());
    ShapeData shape;
    shape.kind = ShapeKind::kBox;
    shape.size = box.hi - box.lo;
    shapes->push_back(PlaceShape(shape, Pose{(box.lo + box.hi) * 0.5, {}}, ObjectId{}, -1));
    double a[3], b[3];
    bool inside = true;
    for (int i = 0; i < 3; ++i) {
      a[i] = std::floor((Axis(box.lo, i) + shrink) * inv_resolution) + key_offset[i];
      b[i] = std::floor((Axis(box.hi, i) - shrink) * inv_resolution) + key_offset[i];
      inside = inside && a[i] >= 0 && b[i] <= kMaxKey;
    }
    if (!inside) {  // beyond the octree: tested one by one
      far->push_back(s);
      continue;
    }
    int lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
      lo[i] = static_cast<int>(a[i]), hi[i] = std::max(static_cast<int>(b[i]), lo[i]);
      key_lo[i] = std::min(key_lo[i], lo[i]);
      key_hi[i] = std::max(key_hi[i], hi[i]);
    }
    if (tree->getRoot() == nullptr)  // the library makes the root (and a path to a voxel)
      tree->setNodeValue(octomap::OcTreeKey(lo[0], lo[1], lo[2]), occupied, /*lazy_eval=*/true);
    const int origin[3] = {0, 0, 0};
    InsertKeyBox(tree, tree->getRoot(), origin, kTreeSize, lo, hi, occupied, false, &nodes);
    if (nodes > kMaxNodes) {
      std::ostringstream m;
      m << "proximity: the environment map " << map.source << " needs more than " << kMaxNodes
        << " octree nodes at octree_resolution " << resolution
        << " m; use a coarser resolution (the map's own is " << map.resolution << " m)";
      throw Error(m.str());
    }
    for (int bx = lo[0] >> kBucketShift; bx <= hi[0] >> kBucketShift; ++bx)
      for (int by = lo[1] >> kBucketShift; by <= hi[1] >> kBucketShift; ++by)
        for (int bz = lo[2] >> kBucketShift; bz <= hi[2] >> kBucketShift; ++bz)
          touches->emplace_back(PackBucket(bx, by, bz), s);
  }
}
}  // namespace

StaticIndex::StaticIndex() = default;
StaticIndex::~StaticIndex() = default;

// Keys are offsets in voxels from key_offset_ (the key of coordinate 0): at
// kKeyOffset, as octomap places a depth-16 tree's, when the static
// environment lies within 32,768 voxels of the origin, which gives the
// same voxels as ever; else, along each axis where it spans at most 65,536
// voxels, the octree is moved by a whole number of voxels to centre it
// (the voxels' faces stay where they were). Where it spans more, the
// shapes beyond the octree are tested one by one (far_).
void StaticIndex::ChooseKeyOffsets(const EnvironmentMap* map, const std::vector<Vec3>& lo,
                                   const std::vector<Vec3>& hi, double margin) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double key_lo[3] = {kInf, kInf, kInf}, key_hi[3] = {-kInf, -kInf, -kInf};
  const auto grow = [&](const Vec3& a, const Vec3& b) {
    for (int i = 0; i < 3; ++i) {
      key_lo[i] = std::min(key_lo[i], std::floor((Axis(a, i) - margin) * inv_resolution_));
      key_hi[i] = std::max(key_hi[i], std::floor((Axis(b, i) + margin) * inv_resolution_));
    }
  };
  for (size_t s = 0; s < lo.size(); ++s) grow(lo[s], hi[s]);
  if (map != nullptr)
    for (const EnvironmentBox& box : map->boxes) grow(box.lo, box.hi);
  for (int i = 0; i < 3; ++i) {
    key_offset_[i] = kKeyOffset;
    if (!(key_lo[i] <= key_hi[i])) continue;  // nothing static
    if (key_lo[i] + kKeyOffset >= 0 && key_hi[i] + kKeyOffset <= kMaxKey) continue;
    const double span = key_hi[i] - key_lo[i];
    if (span > kMaxKey) continue;  // too wide for any placement: far_ takes the rest
    const double offset = std::floor((kMaxKey - span) / 2) - key_lo[i];
    if (std::abs(offset) <= kMaxShift) key_offset_[i] = static_cast<int>(offset);
  }
}

double StaticIndex::RawKey(double coordinate, int axis) const {
  return std::floor(coordinate * inv_resolution_) + key_offset_[axis];
}

int StaticIndex::ClampedKey(double coordinate, int axis) const {
  // floor() by truncation, in a range where int holds it exactly; values
  // beyond clamp to keys beyond every voxel, as RawKey's would be.
  const double scaled = std::clamp(coordinate * inv_resolution_, -1e9, 1e9);
  const int truncated = static_cast<int>(scaled);
  return truncated - (scaled < truncated ? 1 : 0) + key_offset_[axis];
}

size_t StaticIndex::octree_node_count() const { return tree_ ? tree_->size() : 0; }

void StaticIndex::Build(const Scene& scene, double resolution, std::span<const uint32_t> left_out) {
  if (!(resolution > 0) || !std::isfinite(resolution)) {
    std::ostringstream m;
    m << "proximity: octree_resolution must be a positive number of metres, got " << resolution;
    throw Error(m.str());
  }
  resolution_ = resolution;
  inv_resolution_ = 1 / resolution;
  tree_ = std::make_unique<octomap::OcTree>(resolution);
  shapes_.clear();
  meshes_.clear();
  buckets_.clear();
  bucket_shapes_.clear();
  coarse_.clear();
  blocks_.clear();
  far_.clear();
  far_lo_.clear();
  far_hi_.clear();

  // The static shapes, in slot order (independent of table history).
  const auto shape_rows = scene.shapes();
  const auto owners = scene.shape_owners();
  for (size_t r = 0; r < shape_rows.size(); ++r) {
    const uint32_t slot = owners[r];
    if (!scene.alive_at(slot) || scene.instance_of_at(slot) >= 0 || shape_rows[r].dynamic) continue;
    if (std::binary_search(left_out.begin(), left_out.end(), slot)) continue;
    shapes_.push_back(PlaceShape(shape_rows[r], scene.world_pose_at(slot), scene.IdAt(slot), -1));
    if (shape_rows[r].mesh) meshes_.push_back(shape_rows[r].mesh);
  }
  std::sort(shapes_.begin(), shapes_.end(),
            [](const PlacedShape& a, const PlacedShape& b) { return a.id.index1 < b.id.index1; });

  // Every shape's bounds are finite (a world file's always are; a script's
  // pose may not be).
  const double margin = resolution * 1e-6;  // grows shapes a hair: robust on voxel faces
  std::vector<Vec3> shape_lo(shapes_.size()), shape_hi(shapes_.size());
  for (uint32_t s = 0; s < shapes_.size(); ++s) {
    WorldBounds(shapes_[s], &shape_lo[s], &shape_hi[s]);
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(Axis(shape_lo[s], i)) || !std::isfinite(Axis(shape_hi[s], i))) {
        std::ostringstream m;
        m << "proximity: static shape '" << scene.PathOf(shapes_[s].id)
          << "' has a non-finite pose or size";
        throw Error(m.str());
      }
  }
  ChooseKeyOffsets(scene.environment(), shape_lo, shape_hi, margin);

  // Mark the voxels each shape may overlap; remember the buckets it touches.
  // A shape beyond the octree's keys is tested one by one instead (far_).
  const float occupied = tree_->getClampingThresMaxLog();
  const double half = resolution / 2;
  std::vector<std::pair<uint64_t, uint32_t>> touches;  // (bucket, shape)
  for (int i = 0; i < 3; ++i) occupied_keys_.lo[i] = kMaxKey, occupied_keys_.hi[i] = 0;
  double voxel_tests = 0;
  for (uint32_t s = 0; s < shapes_.size(); ++s) {
    const PlacedShape& shape = shapes_[s];
    double klo[3], khi[3];
    bool inside = true;
    for (int i = 0; i < 3; ++i) {
      klo[i] = RawKey(Axis(shape_lo[s], i) - margin, i);
      khi[i] = RawKey(Axis(shape_hi[s], i) + margin, i);
      inside = inside && klo[i] >= 0 && khi[i] <= kMaxKey;
    }
    if (!inside) {
      far_.push_back(s);
      continue;
    }
    voxel_tests += (khi[0] - klo[0] + 1) * (khi[1] - klo[1] + 1) * (khi[2] - klo[2] + 1);
    if (voxel_tests > kMaxVoxelTests) {
      std::ostringstream m;
      m << "proximity: the static environment spans more than " << kMaxVoxelTests
        << " voxels at octree_resolution " << resolution << " m (at shape '"
        << scene.PathOf(shape.id) << "'); use a coarser resolution";
      throw Error(m.str());
    }
    int k0[3], k1[3];
    for (int i = 0; i < 3; ++i) k0[i] = static_cast<int>(klo[i]), k1[i] = static_cast<int>(khi[i]);
    for (int bx = k0[0] >> kBucketShift; bx <= k1[0] >> kBucketShift; ++bx)
      for (int by = k0[1] >> kBucketShift; by <= k1[1] >> kBucketShift; ++by)
        for (int bz = k0[2] >> kBucketShift; bz <= k1[2] >> kBucketShift; ++bz) {
          bool touched = false;
          const int b[3] = {bx, by, bz};
          int v0[3], v1[3];
          for (int i = 0; i < 3; ++i) {
            v0[i] = std::max(b[i] << kBucketShift, k0[i]);
            v1[i] = std::min((b[i] << kBucketShift) + (1 << kBucketShift) - 1, k1[i]);
          }
          for (int x = v0[0]; x <= v1[0]; ++x)
            for (int y = v0[1]; y <= v1[1]; ++y)
              for (int z = v0[2]; z <= v1[2]; ++z) {
                const Vec3 centre{(x - key_offset_[0] + 0.5) * resolution,
                                  (y - key_offset_[1] + 0.5) * resolution,
                                  (z - key_offset_[2] + 0.5) * resolution};
                if (!MayOverlapCube(shape, centre, half, margin)) continue;
                tree_->setNodeValue(octomap::OcTreeKey(x, y, z), occupied, /*lazy_eval=*/true);
                touched = true;
                const int k[3] = {x, y, z};
                for (int i = 0; i < 3; ++i) {
                  occupied_keys_.lo[i] = std::min(occupied_keys_.lo[i], k[i]);
                  occupied_keys_.hi[i] = std::max(occupied_keys_.hi[i], k[i]);
                }
              }
          if (touched) touches.emplace_back(PackBucket(bx, by, bz), s);
        }
  }
  // The environment map's voxels: boxes of no object, after the shapes.
  if (const EnvironmentMap* map = scene.environment())
    AddEnvironment(*map, resolution, key_offset_, tree_.get(), &shapes_, &far_, &touches,
                   occupied_keys_.lo, occupied_keys_.hi);
  for (const uint32_t s : far_) {
    Vec3 lo, hi;
    WorldBounds(shapes_[s], &lo, &hi);
    far_lo_.push_back(lo);
    far_hi_.push_back(hi);
  }
  tree_->updateInnerOccupancy();
  tree_->prune();

  // Bucket -> shapes, as ranges of one flat array.
  std::sort(touches.begin(), touches.end());
  touches.erase(std::unique(touches.begin(), touches.end()), touches.end());
  bucket_shapes_.reserve(touches.size());
  buckets_.reserve(touches.size());
  for (size_t e = 0; e < touches.size();) {
    const uint64_t bucket = touches[e].first;
    const uint32_t begin = static_cast<uint32_t>(bucket_shapes_.size());
    for (; e < touches.size() && touches[e].first == bucket; ++e)
      bucket_shapes_.push_back(touches[e].second);
    buckets_.emplace(bucket, std::make_pair(begin, static_cast<uint32_t>(bucket_shapes_.size())));
  }

  occupied_lo_ = {(occupied_keys_.lo[0] - key_offset_[0]) * resolution,
                  (occupied_keys_.lo[1] - key_offset_[1]) * resolution,
                  (occupied_keys_.lo[2] - key_offset_[2]) * resolution};
  occupied_hi_ = {(occupied_keys_.hi[0] + 1 - key_offset_[0]) * resolution,
                  (occupied_keys_.hi[1] + 1 - key_offset_[1]) * resolution,
                  (occupied_keys_.hi[2] + 1 - key_offset_[2]) * resolution};
  BuildCoarseMap();
}

void StaticIndex::BuildCoarseMap() {
  coarse_.clear();
  blocks_.clear();
  if (shapes_.empty() || tree_->getRoot() == nullptr) return;  // AnyOccupied: always false
  // Finest cells that fit: z in one 64-bit mask, the (x, y) columns in the budget.
  int span[3];
  for (int i = 0; i < 3; ++i) span[i] = occupied_keys_.hi[i] - occupied_keys_.lo[i] + 1;
  auto cells = [&](int i, int shift) { return ((span[i] - 1) >> shift) + 1; };
  int shift_z = 0, shift_xy = 0;
  while (cells(2, shift_z) > kCoarseZCells) ++shift_z;
  while (int64_t{cells(0, shift_xy)} * cells(1, shift_xy) > kMaxCoarseColumns) ++shift_xy;
  coarse_shift_[0] = coarse_shift_[1] = shift_xy;
  coarse_shift_[2] = shift_z;
  for (int i = 0; i < 3; ++i) coarse_size_[i] = cells(i, coarse_shift_[i]);
  for (int i = 0; i < 2; ++i) block_count_[i] = ((coarse_size_[i] - 1) >> kBlockShift) + 1;
  coarse_.assign(size_t(block_count_[0]) * size_t(block_count_[1]) << (2 * kBlockShift), 0);
  const int origin[3] = {0, 0, 0};
  MarkCoarse(tree_->getRoot(), origin, kTreeSize);
  blocks_.assign(size_t(block_count_[0]) * size_t(block_count_[1]), 0);
  for (int x = 0; x < coarse_size_[0]; ++x)
    for (int y = 0; y < coarse_size_[1]; ++y)
      blocks_[size_t(x >> kBlockShift) * block_count_[1] + (y >> kBlockShift)] |=
          coarse_[ColumnIndex(x, y)];
}

bool StaticIndex::CoarseCellOccupied(const int key[3]) const {
  int cell[3];
  for (int i = 0; i < 3; ++i) cell[i] = (key[i] - occupied_keys_.lo[i]) >> coarse_shift_[i];
  return (coarse_[ColumnIndex(cell[0], cell[1])] >> cell[2]) & 1;
}

size_t StaticIndex::ColumnIndex(int x, int y) const {
  constexpr int kMask = (1 << kBlockShift) - 1;
  const size_t block = size_t(x >> kBlockShift) * block_count_[1] + (y >> kBlockShift);
  return (block << (2 * kBlockShift)) | size_t((x & kMask) << kBlockShift | (y & kMask));
}

void StaticIndex::MarkCoarse(const octomap::OcTreeNode* node, const int origin[3], int size) {
  // The same walk as AnyOccupiedIn: an occupied node without children is a
  // voxel or a pruned occupied block.
  if (!tree_->isNodeOccupied(node)) return;
  if (tree_->nodeHasChildren(node)) {
    const int half = size / 2;
    for (unsigned int c = 0; c < 8; ++c) {
      if (!tree_->nodeChildExists(node, c)) continue;
      const int child[3] = {origin[0] + ((c & 1) ? half : 0), origin[1] + ((c & 2) ? half : 0),
                            origin[2] + ((c & 4) ? half : 0)};
      MarkCoarse(tree_->getNodeChild(node, c), child, half);
    }
    return;
  }
  int lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    const int a = std::max(origin[i], occupied_keys_.lo[i]);
    const int b = std::min(origin[i] + size - 1, occupied_keys_.hi[i]);
    if (a > b) return;  // (no occupied voxel lies outside occupied_keys_)
    lo[i] = (a - occupied_keys_.lo[i]) >> coarse_shift_[i];
    hi[i] = (b - occupied_keys_.lo[i]) >> coarse_shift_[i];
  }
  uint16_t z_mask = 0;
  for (int z = lo[2]; z <= hi[2]; ++z) z_mask |= uint16_t(1u << z);
  for (int x = lo[0]; x <= hi[0]; ++x)
    for (int y = lo[1]; y <= hi[1]; ++y) coarse_[ColumnIndex(x, y)] |= z_mask;
}

bool StaticIndex::MayBeOccupied(const Vec3& lo, const Vec3& hi) const {
  if (!far_.empty() && FarOverlaps(lo, hi)) return true;
  if (coarse_.empty()) return false;  // no occupied voxel
  const double box_lo[3] = {lo.x, lo.y, lo.z}, box_hi[3] = {hi.x, hi.y, hi.z};
  const double occupied_lo[3] = {occupied_lo_.x, occupied_lo_.y, occupied_lo_.z};
  const double occupied_hi[3] = {occupied_hi_.x, occupied_hi_.y, occupied_hi_.z};
  int cell_lo[3], cell_hi[3];
  for (int i = 0; i < 3; ++i) {
    // AnyOccupied's box test and key box (written so that NaN bounds answer
    // "no", as there). A key box the clamp turns inside out holds no
    // occupied voxel: every one lies within occupied_keys_.
    if (!(box_lo[i] <= occupied_hi[i] && box_hi[i] >= occupied_lo[i])) return false;
    const int key_lo = occupied_keys_.lo[i], key_hi = occupied_keys_.hi[i];
    const int a = std::max(ClampedKey(box_lo[i], i), key_lo);
    const int b = std::min(ClampedKey(box_hi[i], i), key_hi);
    if (a > b) return false;
    cell_lo[i] = (a - key_lo) >> coarse_shift_[i];
    cell_hi[i] = (b - key_lo) >> coarse_shift_[i];
  }
  const int z_cells = cell_hi[2] - cell_lo[2] + 1;
  const uint16_t z_mask =
      uint16_t((z_cells >= kCoarseZCells ? 0xffffu : (1u << z_cells) - 1) << cell_lo[2]);
  // Blocks first: most boxes are far from every wall.
  for (int bx = cell_lo[0] >> kBlockShift; bx <= cell_hi[0] >> kBlockShift; ++bx)
    for (int by = cell_lo[1] >> kBlockShift; by <= cell_hi[1] >> kBlockShift; ++by) {
      const size_t block = size_t(bx) * block_count_[1] + by;
      if (!(blocks_[block] & z_mask)) continue;
      // The block's columns, x-major, 8 per row.
      constexpr int kMask = (1 << kBlockShift) - 1;
      const uint16_t* columns = &coarse_[block << (2 * kBlockShift)];
      const int x0 = std::max(cell_lo[0], bx << kBlockShift) & kMask;
      const int x1 = std::min(cell_hi[0], ((bx + 1) << kBlockShift) - 1) & kMask;
      const int y0 = std::max(cell_lo[1], by << kBlockShift) & kMask;
      const int y1 = std::min(cell_hi[1], ((by + 1) << kBlockShift) - 1) & kMask;
      for (int x = x0; x <= x1; ++x) {
        const uint16_t* row = columns + (x << kBlockShift);
        for (int y = y0; y <= y1; ++y)
          if (row[y] & z_mask) return true;
      }
    }
  return false;
}

bool StaticIndex::AnyOccupiedIn(const octomap::OcTreeNode* node, const int origin[3], int size,
                                const KeyBox& box) const {
  if (!tree_->isNodeOccupied(node)) return false;
  if (!tree_->nodeHasChildren(node)) return true;  // a voxel, or a pruned occupied block
  const int half = size / 2;
  for (unsigned int c = 0; c < 8; ++c) {
    if (!tree_->nodeChildExists(node, c)) continue;
    const int child[3] = {origin[0] + ((c & 1) ? half : 0), origin[1] + ((c & 2) ? half : 0),
                          origin[2] + ((c & 4) ? half : 0)};
    bool overlaps = true;
    for (int i = 0; i < 3; ++i)
      overlaps = overlaps && child[i] <= box.hi[i] && child[i] + half - 1 >= box.lo[i];
    if (overlaps && AnyOccupiedIn(tree_->getNodeChild(node, c), child, half, box)) return true;
  }
  return false;
}

bool StaticIndex::FarOverlaps(const Vec3& lo, const Vec3& hi) const {
  for (size_t f = 0; f < far_.size(); ++f)
    if (far_lo_[f].x <= hi.x && far_hi_[f].x >= lo.x && far_lo_[f].y <= hi.y &&
        far_hi_[f].y >= lo.y && far_lo_[f].z <= hi.z && far_hi_[f].z >= lo.z)
      return true;
  return false;
}

bool StaticIndex::AnyOccupied(const Vec3& lo, const Vec3& hi) const {
  if (!far_.empty() && FarOverlaps(lo, hi)) return true;
  if (shapes_.empty() || tree_->getRoot() == nullptr) return false;
  KeyBox box;
  for (int i = 0; i < 3; ++i) {
    // (Written so that NaN bounds answer "no".)
    if (!(Axis(lo, i) <= Axis(occupied_hi_, i) && Axis(hi, i) >= Axis(occupied_lo_, i)))
      return false;
    box.lo[i] = static_cast<int>(std::max(RawKey(Axis(lo, i), i), double(occupied_keys_.lo[i])));
    box.hi[i] = static_cast<int>(std::min(RawKey(Axis(hi, i), i), double(occupied_keys_.hi[i])));
  }
  const int origin[3] = {0, 0, 0};
  return AnyOccupiedIn(tree_->getRoot(), origin, kTreeSize, box);
}

const octomap::OcTreeNode* StaticIndex::Descend(const octomap::OcTreeNode* node, int bit,
                                                const int key[3]) const {
  for (; bit >= 0; --bit) {
    const unsigned int child =
        ((key[0] >> bit) & 1) | (((key[1] >> bit) & 1) << 1) | (((key[2] >> bit) & 1) << 2);
    if (!tree_->nodeChildExists(node, child)) return tree_->nodeHasChildren(node) ? nullptr : node;
    node = tree_->getNodeChild(node, child);
  }
  return node;
}

const octomap::OcTreeNode* StaticIndex::CommonAncestor(const int lo[3], const int hi[3],
                                                       int* bit) const {
  const octomap::OcTreeNode* node = tree_->getRoot();
  if (node == nullptr) return nullptr;
  // Keys of the box agree on every bit above the highest differing one.
  const unsigned int differ = (lo[0] ^ hi[0]) | (lo[1] ^ hi[1]) | (lo[2] ^ hi[2]);
  const int free_bits = differ == 0 ? 0 : 32 - __builtin_clz(differ);
  for (*bit = kTreeDepth - 1; *bit >= free_bits; --*bit) {
    const unsigned int child =
        ((lo[0] >> *bit) & 1) | (((lo[1] >> *bit) & 1) << 1) | (((lo[2] >> *bit) & 1) << 2);
    if (!tree_->nodeChildExists(node, child))
      return tree_->nodeHasChildren(node) ? nullptr : node;  // empty, or a pruned full block
    node = tree_->getNodeChild(node, child);
  }
  return node;
}

bool StaticIndex::CastRay(const Vec3& p_W, const Vec3& d_W, double max_t,
                          std::span<const ObjectId> skip, double* t, uint32_t* shape) const {
  if (shapes_.empty()) return false;
  double best = std::numeric_limits<double>::infinity();
  uint32_t best_shape = 0;
  if (CastRayInOctree(p_W, d_W, max_t, skip, &best, &best_shape) && far_.empty()) {
    *t = best;
    *shape = best_shape;
    return true;
  }
  // The shapes beyond the octree, one by one (the lower shape wins a tie).
  for (const uint32_t s : far_) {
    if (std::find(skip.begin(), skip.end(), shapes_[s].id) != skip.end()) continue;
    double hit;
    if (RayCast(shapes_[s], p_W, d_W, max_t, &hit) &&
        (hit < best || (hit == best && s < best_shape)))
      best = hit, best_shape = s;
  }
  if (!(best <= max_t)) return false;
  *t = best;
  *shape = best_shape;
  return true;
}

bool StaticIndex::CastRayInOctree(const Vec3& p_W, const Vec3& d_W, double max_t,
                                  std::span<const ObjectId> skip, double* t,
                                  uint32_t* shape) const {
  // Clip the ray to the box of occupied voxels.
  double t0 = 0, t1 = max_t;
  for (int i = 0; i < 3; ++i)
    if (!ClipSlab(Axis(p_W, i), Axis(d_W, i), Axis(occupied_lo_, i), Axis(occupied_hi_, i), &t0,
                  &t1))
      return false;
  if (!(t0 <= t1)) return false;

  // Key box of the clipped segment, one voxel wider for rounding.
  const double p[3] = {p_W.x, p_W.y, p_W.z}, d[3] = {d_W.x, d_W.y, d_W.z};
  int box_lo[3], box_hi[3];
  for (int i = 0; i < 3; ++i) {
    const double lo = double(occupied_keys_.lo[i]), hi = double(occupied_keys_.hi[i]);
    const double a = std::clamp(RawKey(p[i] + d[i] * t0, i), lo, hi);
    const double b = std::clamp(RawKey(p[i] + d[i] * t1, i), lo, hi);
    box_lo[i] = std::max(static_cast<int>(std::min(a, b)) - 1, 0);
    box_hi[i] = std::min(static_cast<int>(std::max(a, b)) + 1, kMaxKey);
  }
  // The deepest octree node holding that box (none means no occupied voxel
  // on the ray): found at the first voxel the coarse map does not rule out.
  int bit = 0;
  const octomap::OcTreeNode* top = nullptr;
  bool top_found = false;

  // 3D DDA (Amanatides & Woo) over voxel keys, from the clipped entry point.
  int key[3], step[3];
  double t_max[3], t_delta[3];
  for (int i = 0; i < 3; ++i) {
    const double entry = RawKey(p[i] + d[i] * t0, i);
    key[i] = static_cast<int>(
        std::clamp(entry, double(occupied_keys_.lo[i]), double(occupied_keys_.hi[i])));
    step[i] = d[i] > 0 ? 1 : d[i] < 0 ? -1 : 0;
    if (step[i] == 0) {
      t_max[i] = t_delta[i] = std::numeric_limits<double>::infinity();
      continue;
    }
    const double face = (key[i] + (step[i] > 0 ? 1 : 0) - key_offset_[i]) * resolution_;
    t_max[i] = (face - p[i]) / d[i];
    t_delta[i] = resolution_ / std::abs(d[i]);
  }

  double best = std::numeric_limits<double>::infinity();
  uint32_t best_shape = 0;
  uint32_t tested[kTestedCapacity];
  int tested_count = 0;
  for (;;) {
    // An occupied voxel: test its bucket's shapes exactly (once per ray).
    // (Where the coarse map has nothing, Descend would find nothing.)
    const octomap::OcTreeNode* node = nullptr;
    if (CoarseCellOccupied(key)) {
      if (!top_found) {
        top = CommonAncestor(box_lo, box_hi, &bit);
        top_found = true;
        if (top == nullptr) return false;
      }
      node = Descend(top, bit, key);
    }
    if (node != nullptr && tree_->isNodeOccupied(node)) {
      const auto it = buckets_.find(
          PackBucket(key[0] >> kBucketShift, key[1] >> kBucketShift, key[2] >> kBucketShift));
      if (it != buckets_.end()) {
        for (uint32_t e = it->second.first; e < it->second.second; ++e) {
          const uint32_t s = bucket_shapes_[e];
          if (std::find(tested, tested + tested_count, s) != tested + tested_count) continue;
          if (tested_count < kTestedCapacity) tested[tested_count++] = s;
          if (std::find(skip.begin(), skip.end(), shapes_[s].id) != skip.end()) continue;
          double hit;
          if (RayCast(shapes_[s], p_W, d_W, max_t, &hit) && hit < best) best = hit, best_shape = s;
        }
      }
    }
    // Next voxel; stop past the clipped ray or past the best hit so far.
    const int axis =
        t_max[0] <= t_max[1] ? (t_max[0] <= t_max[2] ? 0 : 2) : (t_max[1] <= t_max[2] ? 1 : 2);
    if (!(t_max[axis] <= std::min(best, t1))) break;
    key[axis] += step[axis];
    if (key[axis] < std::max(box_lo[axis], occupied_keys_.lo[axis]) ||
        key[axis] > std::min(box_hi[axis], occupied_keys_.hi[axis]))
      break;
    t_max[axis] += t_delta[axis];
  }
  if (!(best <= max_t)) return false;
  *t = best;
  *shape = best_shape;
  return true;
}

void StaticIndex::ShapesInBox(const Vec3& lo, const Vec3& hi, std::vector<uint32_t>* out) const {
  out->clear();
  if (shapes_.empty()) return;
  ShapesInBoxInOctree(lo, hi, out);
  if (far_.empty()) return;
  // The shapes beyond the octree whose bounds meet the box (a non-finite
  // box: every one).
  const bool any = std::isnan(lo.x) || std::isnan(lo.y) || std::isnan(lo.z) || std::isnan(hi.x) ||
                   std::isnan(hi.y) || std::isnan(hi.z);
  for (size_t f = 0; f < far_.size(); ++f)
    if (any || (far_lo_[f].x <= hi.x && far_hi_[f].x >= lo.x && far_lo_[f].y <= hi.y &&
                far_hi_[f].y >= lo.y && far_lo_[f].z <= hi.z && far_hi_[f].z >= lo.z))
      out->push_back(far_[f]);
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

void StaticIndex::ShapesInBoxInOctree(const Vec3& lo, const Vec3& hi,
                                      std::vector<uint32_t>* out) const {
  // The box's keys within the occupied ones (a non-finite box: every key).
  int k0[3], k1[3];
  for (int i = 0; i < 3; ++i) {
    const double a = Axis(lo, i), b = Axis(hi, i);
    k0[i] = std::isnan(a) ? occupied_keys_.lo[i] : std::max(ClampedKey(a, i), occupied_keys_.lo[i]);
    k1[i] = std::isnan(b) ? occupied_keys_.hi[i] : std::min(ClampedKey(b, i), occupied_keys_.hi[i]);
    if (k0[i] > k1[i]) return;
  }
  double buckets = 1;
  for (int i = 0; i < 3; ++i) buckets *= (k1[i] >> kBucketShift) - (k0[i] >> kBucketShift) + 1;
  // More buckets than shapes: scan the shapes' bounds instead.
  if (buckets > static_cast<double>(std::min(buckets_.size(), shapes_.size()))) {
    for (uint32_t s = 0; s < shapes_.size(); ++s) {
      Vec3 a, b;
      WorldBounds(shapes_[s], &a, &b);
      if (a.x <= hi.x && b.x >= lo.x && a.y <= hi.y && b.y >= lo.y && a.z <= hi.z && b.z >= lo.z)
        out->push_back(s);
    }
    return;
  }
  for (int bx = k0[0] >> kBucketShift; bx <= k1[0] >> kBucketShift; ++bx)
    for (int by = k0[1] >> kBucketShift; by <= k1[1] >> kBucketShift; ++by)
      for (int bz = k0[2] >> kBucketShift; bz <= k1[2] >> kBucketShift; ++bz) {
        const auto it = buckets_.find(PackBucket(bx, by, bz));
        if (it == buckets_.end()) continue;
        for (uint32_t e = it->second.first; e < it->second.second; ++e)
          out->push_back(bucket_shapes_[e]);
      }
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

}  // namespace swarmsim::proximity
