// The rows of the mill module's object types (objects.cc): mills and
// cuttable blocks. A cuttable's voxels live in the module (module.h), one
// bitset per block; its row keeps the grid and what the state hash and the
// scripts read (remaining voxels, a digest of the removed ones). Internal
// to modules/mill.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "framework/math.h"
#include "modules/mill/volume.h"

namespace swarmsim::mill {

struct MillRow {
  // Settings.
  Volume volume;
  bool enabled = true;
  bool record = true;  // `<name>.removed` into metrics.csv
  // The reading, after each step's cut.
  double removed = 0;        // m^3 removed this step (cuttables and the map)
  double removed_total = 0;  // m^3 since the start
};

// Voxels one cuttable may have (the reader refuses more, naming the count).
inline constexpr double kMaxVoxels = 50e6;

struct CuttableRow {
  // Settings: a box of `size` centred on the object, divided into
  // nx x ny x nz voxels of at most `resolution` per side. Scaling scales
  // size and resolution and keeps the grid.
  Vec3 size{0.1, 0.1, 0.1};   // m
  double resolution = 0.005;  // m, the voxel edge asked for
  Vec3 color{0.6, 0.45, 0.3};
  bool record = true;  // `<name>.remaining` into metrics.csv
  uint32_t nx = 20, ny = 20, nz = 20;
  // State: voxels left, and the wrapping sum of Mix(index) over the removed
  // ones (order-free, so equal cuts give equal digests).
  int64_t remaining = 8000;
  uint64_t digest = 0;

  int64_t voxel_count() const { return int64_t{nx} * ny * nz; }
  Vec3 voxel_size() const { return {size.x / nx, size.y / ny, size.z / nz}; }
  double voxel_volume() const {
    return size.x * size.y * size.z / static_cast<double>(voxel_count());
  }
};

// Voxels per axis for a block side and a resolution (at least 1).
inline uint32_t VoxelsAlong(double side, double resolution) {
  return static_cast<uint32_t>(std::max(1.0, std::ceil(side / resolution - 1e-9)));
}

// SplitMix64's finaliser: the digest's per-voxel term.
inline uint64_t Mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace swarmsim::mill
