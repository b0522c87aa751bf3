// Collections (V-REP): named groups of scene objects, for collision and
// distance objects, sensors' detectable sets and scripts.
//
// A collection is an object of type `collection` (framework/types/) whose
// row lists items: an object alone, an object with everything below it (a
// model copy's root: the whole copy), or everything; each item adds its
// objects or, excluded, removes them, in order. Paths are resolved from the
// collection object itself (":" is its model root, ":/arm" an object of its
// model, "/walls" absolute), so a collection inside a model is per copy and
// is copied and removed with it. Scripts make collections of their own
// (sim.createCollection; lua_api_collections.cc) from handles.
//
// Entities are what collision and distance objects measure between: a path
// (a collection stands for its objects; any other object for itself and
// everything below it), "environment" (the static shapes and the map) or
// "everything_else" (every shape but the other side's).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "framework/handle.h"

namespace swarmsim {

class Scene;

enum class CollectionItemKind : uint8_t { kObject, kTree, kAll };

struct CollectionItem {
  CollectionItemKind kind = CollectionItemKind::kTree;
  bool exclude = false;
  std::string path;   // resolved from the collection object; empty: `id`
  ObjectId id;        // an item a script added by handle
  std::string where;  // "file:line:column" of a path from a file, for errors
};

// The row of an object of type collection.
struct CollectionRow {
  std::vector<CollectionItem> items;
};

// Paths in a collection, an entity list or a sensor's `detectable` are
// checked once the world is built (ObjectTypeDescriptor::check): a path
// that matches nothing is an error at its file:line:column.

// What a path that matches nothing (or a stale handle) is: an error (the
// load's check, a script's call), or nothing (a module resolving again at
// run time, after the load checked the path: the robot it named was
// removed, so it names no object now).
enum class Missing : uint8_t { kError, kNone };

// The slots of the objects `items` name, resolved from `from`, ascending.
// Throws swarmsim::Error naming `what` and the item when a path matches
// nothing or a handle is stale (with Missing::kNone: the item adds none).
std::vector<uint32_t> CollectionSlots(const Scene& scene, std::span<const CollectionItem> items,
                                      ObjectId from, std::string_view what,
                                      Missing missing = Missing::kError);
// The same for the collection object `collection`.
std::vector<uint32_t> CollectionSlots(const Scene& scene, ObjectId collection,
                                      Missing missing = Missing::kError);

struct EntitySpec {
  enum Kind : uint8_t { kPath, kEnvironment, kEverythingElse };
  Kind kind = kPath;
  std::string path;
};
// "environment", "everything_else", or a path.
EntitySpec ParseEntity(std::string_view text);
// The slots an entity path names, resolved from `from`, ascending: a
// collection's objects, or the object's subtree. Throws swarmsim::Error
// naming `what` when nothing matches (with Missing::kNone: none).
std::vector<uint32_t> EntitySlots(const Scene& scene, std::string_view path, ObjectId from,
                                  std::string_view what, Missing missing = Missing::kError);

}  // namespace swarmsim
