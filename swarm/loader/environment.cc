#include "swarm/loader/environment.h"

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world_section.h"
#include "swarm/loader/object_reader.h"

namespace swarmsim::loader {

std::shared_ptr<const EnvironmentMap> ReadEnvironment(
    const YamlFile& file, const Field& environment, const ValueReader& values,
    const std::filesystem::path& world_folder, const ModuleRegistry& registry,
    std::vector<std::string>* warnings, const EnvironmentFormatDescriptor** format_out) {
  *format_out = nullptr;
  if (!environment.present()) return nullptr;
  const auto& formats = registry.environment_formats();
  std::string names;  // "octomap", for messages
  for (const auto& format : formats) names += (names.empty() ? "" : ", ") + format->key;
  if (!environment.node.IsMap())
    file.Fail(environment.mark,
              "'environment' must be a mapping such as {octomap: maps/building.bt} (got " +
                  Describe(environment.node) + ")");
  Fields f(file, environment, "'environment'");
  // The format is the one whose key the mapping holds (exactly one).
  const EnvironmentFormatDescriptor* format = nullptr;
  for (const auto& candidate : formats) {
    if (!f.Has(candidate->key)) continue;
    if (format != nullptr)
      values.Fail(f.Get(candidate->key), "'environment' names one map: '" + format->key + "' or '" +
                                             candidate->key + "', not both");
    format = candidate.get();
  }
  if (format == nullptr) {
    // A mapping of one format's other keys lacks that format's key.
    for (const auto& candidate : formats)
      for (const ObjectKey& key : candidate->keys)
        if (f.Has(key.name)) f.Require(candidate->key);  // "'octomap' is required"
    file.Fail(environment.mark,
              "'environment' needs the map file under one of: " +
                  (names.empty() ? std::string("(no map format registered)") : names));
  }
  std::vector<std::string> known = {format->key};
  for (const ObjectKey& key : format->keys) known.push_back(key.name);
  f.Expect(known);
  *format_out = format;
  return format->read(FieldsObjectReader(values, f, nullptr, &registry), world_folder, warnings);
}

}  // namespace swarmsim::loader
