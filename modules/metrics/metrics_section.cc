// The world file's `metrics:` section (worlds/README.md), the metrics
// module's own: a list of metric names or {name, every} maps, each adding
// one instance of a registered metric module (kind "metric": the swarm
// metrics here, the colour-clustering ones of modules/blobs).
#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/suggest.h"
#include "framework/world.h"
#include "framework/world_section.h"
#include "modules/metrics/swarm_metrics.h"

namespace swarmsim::metrics {

namespace {

constexpr ObjectKey kKeys[] = {
    {"name", "required", "a built-in metric (an unknown name lists the suggestions)"},
    {"every", "1", "record every N steps"},
};

void ReadMetrics(const ObjectReader& top, const WorldSectionContext&, World* world) {
  std::vector<std::string> known;  // the registered metric modules
  for (const ModuleDescriptor* metric : world->registry().ModulesOfKind("metric"))
    known.push_back(metric->info.name);
  const std::vector<std::string> keys = {"name", "every"};
  std::map<std::string, std::string> listed;  // metric -> where it is listed
  // A bare name (`- covered_area`) reads as {name: covered_area}.
  for (const std::unique_ptr<ObjectReader>& entry :
       top.Elements("metrics", "metrics", "a metric", "name")) {
    entry->Expect(keys);
    entry->Require("name");
    SwarmMetricSpec spec;
    if (entry->Has("every"))
      spec.every_steps = static_cast<int>(entry->Integer("every", 1, 1 << 30));
    spec.name = entry->String("name", /*required=*/true);
    if (std::find(known.begin(), known.end(), spec.name) == known.end())
      entry->Fail("name", "unknown metric '" + spec.name + "'" + Suggest(spec.name, known));
    // metrics.csv has one column a metric: a second entry would be a second
    // column of the same name.
    if (const auto [first, added] = listed.emplace(spec.name, entry->Where("name")); !added)
      entry->Fail("name", "'" + spec.name + "' is listed already, at " + first->second +
                              ": list a metric once ('every' sets how often it is recorded)");
    try {
      world->AddModule(spec.name, &spec.every_steps);
    } catch (const Error& e) {
      entry->Fail("name", e.what());
    }
  }
}

}  // namespace

std::shared_ptr<const WorldSectionDescriptor> MetricsSection() {
  auto section = std::make_shared<WorldSectionDescriptor>();
  section->key = "metrics";
  section->doc = "swarm metrics recorded as the run goes (metrics.csv)";
  section->keys = kKeys;
  section->read = ReadMetrics;
  return section;
}

}  // namespace swarmsim::metrics
