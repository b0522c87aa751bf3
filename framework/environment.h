// The static environment loaded from a map (`environment: {octomap:
// file.bt}` in a world file): the map's occupied space as axis-aligned boxes
// in the world frame. Proximity, collision, minimum distance, line of sight
// and physics read it from the Scene; the files are read by
// modules/environment (no OctoMap types here). Mills cut it (voxels go).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "framework/math.h"

namespace swarmsim {

struct EnvironmentBox {
  Vec3 lo, hi;  // m, world frame; lo < hi on every axis
};

struct EnvironmentMap {
  std::string source;     // the file as the world names it, for messages
  double resolution = 0;  // m, the map's voxel size
  // The occupied leaves of the map, each a cube of resolution x 2^k
  // (a pruned octree merges eight full children; a z range may cut one to
  // fewer voxel layers), on the map's voxel grid, in the map's own order
  // (deterministic: depth-first from the root).
  std::vector<EnvironmentBox> boxes;
  Vec3 lo, hi;  // bounds of `boxes` (both zero when there are none)
  // What the grids made from the map (modules/environment/voxel_merge.h:
  // physics' boxes, placement) may take, bytes: the world file's
  // `max_memory_mb`, which also bounds the map itself.
  double max_grid_bytes = 2048.0 * (1 << 20);
};

// The occupied cells of the xy plane within a z band, at the map's
// resolution: what an environment format's `occupied_plane` query gives
// (world_section.h) and placement keeps robots clear of. Cell (i, j)
// covers [x0 + i cell, x0 + (i + 1) cell] x [y0 + j cell, ...].
struct EnvironmentPlaneGrid {
  double x0 = 0, y0 = 0, cell = 0;  // m
  int nx = 0, ny = 0;
  std::vector<uint8_t> occupied;  // (ny x nx), row-major: j * nx + i
  bool empty() const { return occupied.empty(); }
  bool at(int i, int j) const { return occupied[size_t(j) * size_t(nx) + size_t(i)] != 0; }
};

}  // namespace swarmsim
