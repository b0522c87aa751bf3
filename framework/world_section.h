// World-file sections that modules own: a top-level key of the world file
// (`paint:`, `metrics:`) that a module reads itself, declared in the
// ModuleRegistry with its keys and docs as an object type declares its own
// (object_type.h). The loader knows its own keys (simulation, arena,
// models, ...); every other top-level key is a registered section's, so
// that the loader names no module and an unknown key still lists them all
// ("did you mean 'paint'?").
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "framework/environment.h"
#include "framework/object_type.h"

namespace swarmsim {

class World;

// What the loader knows of the world that a section may need.
struct WorldSectionContext {
  struct Area {
    double min_x, min_y, max_x, max_y;  // m
  };
  std::optional<Area> arena;           // the inner area of the world's `arena:`, if it has one
  std::filesystem::path world_folder;  // the world file's folder: files it names are relative to it
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

// A map format of the world's `environment:` key (`environment: {octomap:
// maps/building.bt, z_range: [0, 2]}`), declared by the module that reads
// it (modules/environment: octomap). The loader takes the format whose key
// the mapping holds and hands it the mapping: it names no format itself.
struct EnvironmentFormatDescriptor {
  std::string key;  // the key naming the map file: "octomap"
  std::string doc;  // one line (worlds/README.md has its keys)
  // The keys beside `key` (offset, z_range, ...), with their defaults and
  // one documentation line each.
  std::span<const ObjectKey> keys;
  // Reads the map the mapping names (a path relative to `world_folder`).
  // Errors name file:line:column through `r` (r.Fail(key, ...)); what may
  // surprise without being wrong (a map without occupied voxels) goes to
  // `warnings`, each starting with its place (r.Where(key)).
  std::function<std::shared_ptr<const EnvironmentMap>(const ObjectReader& r,
                                                      const std::filesystem::path& world_folder,
                                                      std::vector<std::string>* warnings)>
      read;
  // The map's occupied cells of the xy plane within the z band (z_lo, z_hi)
  // m, at the map's resolution: a cell is occupied if a voxel of its column
  // reaches into the band. Placement keeps robots clear of them (the band
  // from the ground to the tallest copy). Throws swarmsim::Error when the
  // grid would take more than the map allows. Null: placement does not
  // see the map.
  std::function<EnvironmentPlaneGrid(const EnvironmentMap& map, double z_lo, double z_hi)>
      occupied_plane;
};

}  // namespace swarmsim
