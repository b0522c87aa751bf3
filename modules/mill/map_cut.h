// Mills cutting the environment map (framework/environment.h): the map's
// boxes (octree leaves, cubes of resolution x 2^k) that a mill's volume
// touches are split down to the map's resolution where needed, and the
// voxels whose centres lie inside the volume go.
//
// A box is cut recursively: a part whose voxel centres all lie inside the
// (convex) volume goes whole (its extreme centres are inside); a part
// whose centres' hull misses the volume's bounding box stays whole; else
// it is halved along each axis that has more than one voxel, down to
// single voxels, whose centres are tested. A box from which nothing went
// stays as it was (no needless splitting); the pieces of a cut box take
// its place in the map's order, so the new map's order is deterministic.
//
// Internal to modules/mill.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "framework/environment.h"
#include "framework/math.h"
#include "modules/mill/volume.h"

namespace swarmsim::mill {

// Which of a map's boxes overlap a query box: the boxes grouped by size
// (level k: edge ~ resolution x 2^k), each level a hash grid of cells of
// that edge, keyed by the cell holding the box's low corner, stored flat
// (buckets of a counting sort, no allocation per cell): building it for a
// new map is two passes over the boxes.
class MapIndex {
 public:
  void Build(const EnvironmentMap& map);
  // The map this index was built for (pointer, and its boxes' storage).
  bool Follows(const EnvironmentMap& map) const {
    return map_ == &map && data_ == map.boxes.data() && size_ == map.boxes.size();
  }
  // Indices of the boxes overlapping [lo, hi] (closed), ascending.
  void Query(const Vec3& lo, const Vec3& hi, std::vector<uint32_t>* out) const;

 private:
  struct Level {
    double cell = 0;              // m, the grid's cell edge
    double max_edge = 0;          // m, the largest box edge in the level
    uint64_t mask = 0;            // buckets - 1 (a power of two)
    std::vector<uint32_t> boxes;  // every box of the level, ascending
    std::vector<uint32_t> start;  // bucket b's boxes: entries[start[b] .. start[b + 1])
    std::vector<uint32_t> entries;
  };
  static uint64_t Bucket(int64_t x, int64_t y, int64_t z);
  const EnvironmentMap* map_ = nullptr;
  const EnvironmentBox* data_ = nullptr;
  size_t size_ = 0;
  std::vector<Level> levels_;
};

// Voxels of `resolution` removed from the box [lo, hi] by the volume at
// X_MW (the world in the mill's frame); what is left is appended to *out
// (the box itself when nothing went).
int64_t CutBox(const EnvironmentBox& box, double resolution, const Volume& volume, const Pose& X_MW,
               std::vector<EnvironmentBox>* out);

// One step's cuts of a map, mill after mill.
class MapCutter {
 public:
  // Cuts the map as the previous cuts of the step left it with the volume
  // at X_WM: returns the voxels removed (0 when the volume is not near).
  int64_t Cut(const EnvironmentMap& map, const Volume& volume, const Pose& X_WM);
  // The map after the step's cuts, or null when nothing was cut. Ends the step.
  std::shared_ptr<const EnvironmentMap> Finish(const EnvironmentMap& map);

 private:
  MapIndex index_;
  // The last map Finish made, kept alive so that no later map can take its
  // address while index_ may follow it (the index compares pointers).
  std::shared_ptr<const EnvironmentMap> held_;
  std::map<uint32_t, std::vector<EnvironmentBox>> replaced_;  // box -> what is left of it
  std::vector<uint32_t> hits_;
};

}  // namespace swarmsim::mill
