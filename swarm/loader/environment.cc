#include "swarm/loader/environment.h"

#include "framework/error.h"
#include "modules/environment/octomap_map.h"

namespace swarmsim::loader {

std::shared_ptr<const EnvironmentMap> ReadEnvironment(const YamlFile& file,
                                                      const Field& environment,
                                                      const ValueReader& values,
                                                      const std::filesystem::path& world_folder,
                                                      std::vector<std::string>* warnings) {
  if (!environment.present()) return nullptr;
  if (!environment.node.IsMap())
    file.Fail(environment.mark,
              "'environment' must be a mapping such as {octomap: maps/building.bt} (got " +
                  Describe(environment.node) + ")");
  Fields f(file, environment, "'environment'");
  f.Expect({"octomap", "offset", "z_range", "occupancy_threshold", "max_memory_mb"});
  const Field octomap = f.Require("octomap");
  const std::string name = values.String(octomap);
  if (name.empty()) values.Fail(octomap, "'octomap' must be the path of a .bt or .ot file");
  environment::OctomapOptions options;
  if (f.Has("offset")) options.offset = values.Vector3(f.Get("offset"), kCoordinate);
  if (f.Has("z_range")) {
    const Field range = f.Get("z_range");
    const std::vector<double> z = values.Numbers(range, 2, 2, kCoordinate);
    if (!(z[0] <= z[1])) values.Fail(range, "'z_range' needs [min, max] with min <= max");
    options.z_min = z[0];
    options.z_max = z[1];
  }
  if (f.Has("occupancy_threshold")) {
    static constexpr NumberRule kProbability{"a probability between 0 and 1 (exclusive)", 0,
                                             1 - 1e-12, true};
    options.occupancy_threshold = values.Number(f.Get("occupancy_threshold"), kProbability);
  }
  if (f.Has("max_memory_mb")) {
    static constexpr NumberRule kMegabytes{"a positive number of MiB", 0, 1e9, true};
    options.max_memory_mb = values.Number(f.Get("max_memory_mb"), kMegabytes);
  }
  environment::OctomapReport report;
  try {
    auto map = std::make_shared<const EnvironmentMap>(
        environment::ReadOctomap(world_folder / name, name, options, &report));
    for (const std::string& w : report.warnings)
      warnings->push_back(file.Where(octomap.mark) + ": " + w);
    return map;
  } catch (const Error& e) {
    values.Fail(octomap, e.what());
  }
}

}  // namespace swarmsim::loader
