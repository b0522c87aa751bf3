// The environment map's voxels (framework/environment.h) as the engines'
// static obstacles: those reaching more than kHeightOverlap into the
// dynamic shapes' height range (the rule of static shapes,
// height_range.h), merged greedily into boxes (3D) or plane rectangles
// (modules/environment/voxel_merge.h). Voxels above or below that band
// (floor, ceiling) are not obstacles; the engines' ground stays the floor.
// Engine-neutral.
#pragma once

#include <vector>

#include "framework/environment.h"
#include "framework/scene.h"
#include "modules/dynamics/height_range.h"
#include "modules/environment/voxel_merge.h"

namespace swarmsim::dynamics {

// Empty without a map, without voxels in the band, or for an empty range.
inline std::vector<EnvironmentBox> EnvironmentObstacles(const Scene& scene,
                                                        const HeightRange& dynamic_range,
                                                        bool planar) {
  const EnvironmentMap* map = scene.environment();
  if (map == nullptr || map->boxes.empty()) return {};
  const double lo = dynamic_range.lo + kHeightOverlap, hi = dynamic_range.hi - kHeightOverlap;
  if (!(lo < hi)) return {};
  return planar ? environment::MergeBand2D(*map, lo, hi) : environment::MergeBand3D(*map, lo, hi);
}

}  // namespace swarmsim::dynamics
