// modules/environment's public header: the `octomap` map format of a
// world's `environment:` key, registered with the ModuleRegistry (the
// loader reads the key through the registry and names no format), with
// its `occupied_plane` query: the map's occupied cells in a horizontal band
// for placing robots around them (voxel_merge.h's ProjectBand).
#pragma once

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::environment {

// Registers the `octomap` format (.bt and .ot files, octomap_map.h).
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::environment
