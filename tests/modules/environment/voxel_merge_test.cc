// Merging a band of the environment map's voxels into boxes
// (voxel_merge.cc).

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/dynamics/environment_obstacles.h"
#include "modules/environment/octomap_map.h"
#include "tests/shared_maps.h"

namespace swarmsim {
namespace {

// The shared map at foot-bot height: a few hundred merged boxes that cover
// exactly the band's voxels.
TEST(EnvironmentPhysicsTest, TheSharedMapsBandMergesIntoFewBoxesCoveringItsVoxels) {
  SWARMSIM_NEED_SHARED_MAP(path, "geb079.bt");
  const EnvironmentMap map = environment::ReadOctomap(path, "geb079.bt", {});
  const double lo = 0.001, hi = 0.145;  // a foot-bot's height range, 1 mm in
  int64_t voxels = 0;
  for (const EnvironmentBox& b : map.boxes) {
    const int64_t side = std::lround((b.hi.x - b.lo.x) / 0.08);
    for (int64_t k = 0; k < side; ++k) {
      const double bottom = b.lo.z + k * 0.08;
      if (bottom + 0.08 > lo && bottom < hi) voxels += side * side;
    }
  }
  const auto boxes = environment::MergeBand3D(map, lo, hi);
  int64_t covered = 0;
  for (const EnvironmentBox& b : boxes)
    covered += std::lround((b.hi.x - b.lo.x) / 0.08) * std::lround((b.hi.y - b.lo.y) / 0.08) *
               std::lround((b.hi.z - b.lo.z) / 0.08);
  EXPECT_EQ(covered, voxels);
  EXPECT_LT(boxes.size() * 4, static_cast<size_t>(voxels));
  const auto rects = environment::MergeBand2D(map, lo, hi);
  EXPECT_LT(rects.size(), boxes.size());
  std::printf("geb079.bt, band z %.3f..%.3f m: %lld voxels, %zu boxes (3D), %zu rectangles (2D)\n",
              lo, hi, static_cast<long long>(voxels), boxes.size(), rects.size());
}

}  // namespace
}  // namespace swarmsim
