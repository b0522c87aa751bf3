#include "modules/environment/environment.h"

#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/number_rule.h"
#include "framework/registry.h"
#include "framework/world_section.h"
#include "modules/environment/octomap_map.h"
#include "modules/environment/voxel_merge.h"

namespace swarmsim::environment {
namespace {

constexpr ObjectKey kOctomapKeys[] = {
    {"offset", "[0, 0, 0]", "m, added to every voxel (where the map's origin is in the world)"},
    {"z_range", "all", "[min, max] m: only the voxels whose centres lie in it (after the offset)"},
    {"occupancy_threshold", "0.5", "probability at or above which a voxel is occupied"},
    {"max_memory_mb", "2048",
     "MiB: refuse a map (and the grids made from it) that would take more"},
};

std::shared_ptr<const EnvironmentMap> ReadOctomapEntry(const ObjectReader& r,
                                                       const std::filesystem::path& world_folder,
                                                       std::vector<std::string>* warnings) {
  const std::string name = r.String("octomap", /*required=*/true);
  if (name.empty()) r.Fail("octomap", "'octomap' must be the path of a .bt or .ot file");
  OctomapOptions options;
  if (r.Has("offset")) options.offset = r.Vector3("offset", kCoordinate);
  if (r.Has("z_range")) {
    const std::vector<double> z = r.Numbers("z_range", 2, 2, kCoordinate);
    if (!(z[0] <= z[1])) r.Fail("z_range", "'z_range' needs [min, max] with min <= max");
    options.z_min = z[0];
    options.z_max = z[1];
  }
  if (r.Has("occupancy_threshold")) {
    static constexpr NumberRule kProbability{"a probability between 0 and 1 (exclusive)", 0,
                                             1 - 1e-12, true};
    options.occupancy_threshold = r.Number("occupancy_threshold", kProbability);
  }
  if (r.Has("max_memory_mb")) {
    static constexpr NumberRule kMegabytes{"a positive number of MiB", 0, 1e9, true};
    options.max_memory_mb = r.Number("max_memory_mb", kMegabytes);
  }
  OctomapReport report;
  try {
    auto map = std::make_shared<const EnvironmentMap>(
        ReadOctomap(world_folder / name, name, options, &report));
    for (const std::string& w : report.warnings) warnings->push_back(r.Where("octomap") + ": " + w);
    return map;
  } catch (const Error& e) {
    r.Fail("octomap", e.what());
  }
  return nullptr;  // not reached: Fail throws (a virtual call GCC does not follow)
}

}  // namespace

void Register(ModuleRegistry* registry) {
  auto format = std::make_shared<EnvironmentFormatDescriptor>();
  format->key = "octomap";
  format->doc = "an OctoMap file (.bt or .ot): its occupied voxels, merged into boxes";
  format->keys = kOctomapKeys;
  format->read = ReadOctomapEntry;
  format->occupied_plane = ProjectBand;
  registry->RegisterEnvironmentFormat(std::move(format));
}

}  // namespace swarmsim::environment
