// The world file's `paint:` key (worlds/README.md): the floor paint layer
// that paint nozzles mark, written to the run's outputs as paint.png.
#pragma once

#include <optional>

#include "swarm/loader/placement.h"
#include "swarm/loader/values.h"
#include "swarm/loader/yaml.h"

namespace swarmsim {
class World;
}

namespace swarmsim::loader {

// Adds a paint layer to `world` when the world gives `paint` or its scene
// holds a paint nozzle; its area defaults to the arena's inner area.
void AddPaintLayer(const YamlFile& file, const Field& top_field, const Field& paint,
                   const ValueReader& values, const std::optional<Region2>& arena, World* world);

}  // namespace swarmsim::loader
