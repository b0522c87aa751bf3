// World-file sections that modules own: a top-level key of the world file
// (`paint:`, `metrics:`) that a module reads itself, declared in the
// ModuleRegistry with its keys and docs as an object type declares its own
// (object_type.h). The loader knows its own keys (simulation, arena,
// models, ...); every other top-level key is a registered section's, so
// that the loader names no module and an unknown key still lists them all
// ("did you mean 'paint'?").
#pragma once

#include <functional>
#include <optional>
#include <span>
#include <string>

#include "framework/object_type.h"

namespace swarmsim {

class World;

// What the loader knows of the world that a section may need.
struct WorldSectionContext {
  struct Area {
    double min_x, min_y, max_x, max_y;  // m
  };
  std::optional<Area> arena;  // the inner area of the world's `arena:`, if it has one
};

struct WorldSectionDescriptor {
  std::string key;  // the top-level key, "paint"
  std::string doc;  // one line (worlds/README.md has its `### key` section)
  // The keys its mapping (or each map of its list) takes, with their
  // defaults and one documentation line each (worlds/README.md lists them).
  std::span<const ObjectKey> keys;
  // Reads the section into `world`, once the world's objects exist and are
  // checked. `top` reads the world file's top level: the section reads its
  // own key from it (ObjectReader::Map, Elements) and is called whether the
  // key is there or not (a world with paint nozzles gets a paint layer
  // without `paint:`). Errors name file:line:column through `top`.
  std::function<void(const ObjectReader& top, const WorldSectionContext& context, World* world)>
      read;
};

}  // namespace swarmsim
