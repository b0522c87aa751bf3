// The environment map's voxels in a height band as fewer, larger boxes: what
// the physics engines collide with and what placement keeps clear of. A map
// of 143,729 voxels has a few thousand in the band a swarm moves in, and
// greedy merging makes them a few hundred boxes.
//
// A voxel is in the band (z_lo, z_hi) if its own z extent reaches into it:
// top > z_lo and bottom < z_hi (open: a floor whose top is z_lo is not).
// A pruned leaf counts voxel layer by voxel layer.
//
// Greedy merging on the map's voxel grid: runs of occupied cells along x,
// then runs of equal extent on consecutive rows along y merge into
// rectangles, then (3D) rectangles of equal extent on consecutive layers
// into boxes. Deterministic; the result is sorted by (z, y, x) of the lower
// corner. It covers exactly the occupied cells; it is not the fewest boxes.
//
// The map's boxes must lie on its voxel grid (those ReadOctomap makes do).
// No third-party types here: the engines (modules/dynamics) use it, and
// the loader's placement asks for ProjectBand through the registered format.
#pragma once

#include <cstdint>
#include <vector>

#include "framework/environment.h"

namespace swarmsim::environment {

// The band's voxels merged into boxes (3D: the ODE backend). Throws
// swarmsim::Error if the band's grid would exceed kMaxGridCells.
std::vector<EnvironmentBox> MergeBand3D(const EnvironmentMap& map, double z_lo, double z_hi);
// The band projected onto the plane: a cell is occupied if any voxel of its
// column is in the band; merged into rectangles whose z spans the band's
// voxel layers (2D: the Box2D backend).
std::vector<EnvironmentBox> MergeBand2D(const EnvironmentMap& map, double z_lo, double z_hi);

// The projected band as a grid (placement, through the `octomap` format's
// `occupied_plane` query: framework/world_section.h).
using PlaneGrid = EnvironmentPlaneGrid;
PlaneGrid ProjectBand(const EnvironmentMap& map, double z_lo, double z_hi);

// Cells of a band's grid, at most (1 GiB of bytes: e.g. 16,000 x 16,000 x 4).
inline constexpr int64_t kMaxGridCells = int64_t{1} << 30;

}  // namespace swarmsim::environment
