// The world file's `environment:` key (worlds/README.md): the static
// environment of a map file for proximity sensors, line of sight, physics
// and placement, read by the map format the mapping names (registered by
// a module: modules/environment's `octomap`; framework/world_section.h).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/environment.h"
#include "swarm/loader/values.h"
#include "swarm/loader/yaml.h"

namespace swarmsim {
class ModuleRegistry;
struct EnvironmentFormatDescriptor;
}  // namespace swarmsim

namespace swarmsim::loader {

// Reads the map `environment` names (a path relative to `world_folder`)
// through the format of `registry` whose key it holds. Null when the world
// gives no `environment`. Errors name the key's
// file:line:column and the map's own problem; what may surprise without
// being wrong (a map without occupied voxels) goes to `warnings`. The
// format that read it goes to `format` (its occupied_plane: placement).
std::shared_ptr<const EnvironmentMap> ReadEnvironment(
    const YamlFile& file, const Field& environment, const ValueReader& values,
    const std::filesystem::path& world_folder, const ModuleRegistry& registry,
    std::vector<std::string>* warnings, const EnvironmentFormatDescriptor** format);

}  // namespace swarmsim::loader
