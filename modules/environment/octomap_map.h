// Environments from OctoMap files: a world's `environment: {octomap:
// file.bt}` (or .ot) read into the static environment of its Scene
// (framework/environment.h), for proximity sensors, line of sight and
// physics. OctoMap types stay inside this folder.
//
// The map's occupied leaves (isNodeOccupied at the occupancy threshold)
// become axis-aligned boxes, in depth-first order from the root (children
// 0..7): a deterministic order, the file's own. A pruned leaf (eight full
// children merged) is one box of 2^k voxels per side.
//
// Nothing reaches the OctoMap library unchecked (octomap_format.h): a file
// that is missing, not an OctoMap file, truncated, corrupt, of another tree
// type (.ot) or too large for memory is an Error saying so, never a crash,
// an abort or an unbounded allocation. "Too large" is decided from the
// header's node count before anything is allocated (kBytesPerNode).
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "framework/environment.h"
#include "framework/math.h"

namespace swarmsim::environment {

// Memory a map costs per node of its tree, bytes: the library's tree while
// reading (about 30 measured; 48 with allocator overhead), and per occupied
// leaf its box here, in the proximity index and in its octree (at most one
// leaf per node, about 200). A file whose header's `size` times this
// exceeds OctomapOptions::max_memory_mb is refused before it is read.
inline constexpr double kBytesPerNode = 256;

struct OctomapOptions {
  Vec3 offset;  // m, added to every box (the map's frame in the world)
  // m, world frame (after the offset): only the voxels whose centres lie in
  // [z_min, z_max] are kept (a pruned leaf is cut to those voxel layers).
  double z_min = -std::numeric_limits<double>::infinity();
  double z_max = std::numeric_limits<double>::infinity();
  // Probability at or above which a leaf is occupied (octomap's default 0.5).
  double occupancy_threshold = 0.5;
  double max_memory_mb = 2048;  // refuse maps whose estimate is larger
};

// What a read found, for messages and figures.
struct OctomapReport {
  uint64_t nodes = 0;                 // the tree's nodes (= the header's size)
  uint64_t leaves = 0;                // its leaves (occupied, free; unknown space has none)
  uint64_t occupied_leaves = 0;       // occupied leaves in the file
  uint64_t kept_boxes = 0;            // boxes after z_range
  std::vector<std::string> warnings;  // e.g. no occupied voxel
};

// Reads an OctoMap file. `name` is the file as the user named it (for
// messages and EnvironmentMap::source). Throws swarmsim::Error
// "octomap NAME: what is wrong".
EnvironmentMap ReadOctomap(const std::filesystem::path& file, const std::string& name,
                           const OctomapOptions& options, OctomapReport* report = nullptr);

}  // namespace swarmsim::environment
