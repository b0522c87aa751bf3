// Object-type descriptors: everything the simulator knows about one kind of
// scene object, in one table entry (ARGoS's registered entities; MuJoCo's
// plugin declarations). Scene, the world-file loader, the state hash and the
// Lua host go through these entries; no code outside them switches over
// object types. What an object looks like (the recorder, the renderer and
// the viewer) is its type's `visual` hook (framework/visual.h).
//
// The built-in types are declared in framework/types/ (one file each) and
// listed in framework/types/core_types.cc; a module or plugin adds its own
// with ModuleRegistry::RegisterObjectType, and every World's Scene gets it.
// Adding a type: its file (rows, hooks, keys), one registration line, tests,
// and its section in worlds/README.md (tests/swarm/world_keys_doc_test.cc
// checks that every key is documented).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/number_rule.h"
#include "framework/object_rows.h"
#include "framework/visual.h"

struct lua_State;

namespace swarmsim {

class ModuleRegistry;
class Scene;
class StateHasher;
class StateReader;
class StateWriter;
class TriangleMesh;

// What a type's `read` hook sees of one object entry in a model file: the
// loader's reader behind an interface (no YAML types here). Keys are the
// type's own; `required` ones are an error when absent. Every error names
// file:line:column.
class ObjectReader {
 public:
  virtual ~ObjectReader() = default;
  virtual bool Has(std::string_view key) const = 0;
  virtual double Number(std::string_view key, const NumberRule& rule,
                        bool required = false) const = 0;
  virtual int64_t Integer(std::string_view key, int64_t min, int64_t max) const = 0;
  virtual bool Bool(std::string_view key) const = 0;
  virtual std::string String(std::string_view key, bool required = false) const = 0;
  // One of `choices`, with a suggestion for a near miss.
  virtual std::string Choice(std::string_view key, const std::vector<std::string>& choices,
                             bool required = false) const = 0;
  virtual std::vector<double> Numbers(std::string_view key, size_t min_count, size_t max_count,
                                      const NumberRule& rule) const = 0;
  virtual Vec3 Vector3(std::string_view key, const NumberRule& rule,
                       bool required = false) const = 0;
  // A list of at least `min_count` [x, y, z] lists (`points: [[0, 0, 0],
  // [1, 0, 0]]`); an element's error names its own file:line:column.
  virtual std::vector<Vec3> Vector3List(std::string_view key, size_t min_count,
                                        const NumberRule& rule, bool required = false) const = 0;
  // An error at element `index` of the list at `key`.
  [[noreturn]] virtual void FailAtElement(std::string_view key, size_t index,
                                          const std::string& message) const = 0;
  // A list of strings ([a, b] or a single string); `max_count` at most.
  virtual std::vector<std::string> Strings(std::string_view key, size_t max_count,
                                           bool required = false) const = 0;
  // "file:line:column" of the key's value, for errors found after loading
  // (a path that matches no object: ObjectTypeDescriptor::check).
  virtual std::string Where(std::string_view key) const = 0;
  // An error at the key's value, or at the key itself.
  [[noreturn]] virtual void Fail(std::string_view key, const std::string& message) const = 0;
  [[noreturn]] virtual void FailAtKey(std::string_view key, const std::string& message) const = 0;
  // The triangle mesh file the string at `key` names (relative to the model
  // file), read once per world and scale.
  virtual std::shared_ptr<const TriangleMesh> Mesh(std::string_view key,
                                                   const Vec3& scale) const = 0;
  // The world's registry (plugin sensor types), or null.
  virtual const ModuleRegistry* registry() const = 0;
  // A list of maps (`filters: [{type: grayscale}, {type: blobs, min_pixels: 4}]`):
  // a reader for each map, in order, whose messages name the item
  // ("filters[1] of object 'cam'") and its own file:line:column; none when
  // the key is absent. An element that is not a map is an error. The
  // readers live no longer than this one (use them inside `read`).
  virtual std::vector<std::unique_ptr<ObjectReader>> Items(std::string_view key) const = 0;
  // An error at the first key of this entry that is not among `known`, with
  // the nearest known one ("did you mean 'min_pixels'?"). The loader checks
  // an object's own keys before `read`; an item's are the reader's to check.
  virtual void Expect(std::span<const std::string> known) const = 0;

  // --- Nested values (world-file sections, framework/world_section.h) -------------
  // Readers without them (a test's fake) throw swarmsim::Error.
  // "'key' is required in <what>" when the key is absent or empty.
  virtual void Require(std::string_view key) const;
  // A reader for the mapping at `key`, whose messages name it `what`
  // ("'area'"); null when the key is absent or empty. A value that is not a
  // mapping is an error "'key' must be <expected> (got ...)".
  virtual std::unique_ptr<ObjectReader> Map(std::string_view key, const std::string& what,
                                            std::string_view expected) const;
  // The elements of the list at `key` (`metrics: [a, {name: b, every: 10}]`),
  // a reader each: a map reads as itself (messages name it `what`), any
  // other value as a map holding it under `scalar_key` (a bare name). None
  // when the key is absent; a value that is not a list is an error "'key'
  // must be a list of <list_what> (got ...)".
  virtual std::vector<std::unique_ptr<ObjectReader>> Elements(std::string_view key,
                                                              std::string_view list_what,
                                                              const std::string& what,
                                                              std::string_view scalar_key) const;
  // An error at this entry itself (where its mapping starts).
  [[noreturn]] virtual void FailHere(const std::string& message) const;
  // --- Lists of maps, keys as names (model-file sections, model_section.h) ---------
  // The elements of the list at `key`, each a map read as itself (messages
  // name it `what`); an element that is not a map is an error "<what> must
  // be a mapping of keys to values (got ...)". None when absent.
  virtual std::vector<std::unique_ptr<ObjectReader>> Maps(std::string_view key,
                                                          std::string_view list_what,
                                                          const std::string& what) const;
  // Whether the value at `key` is a list (`constraints: [x, y]` beside `constraints: pose`).
  virtual bool IsList(std::string_view key) const;
  // This entry's keys, in file order (`weights: {j1: 0, j1/j2: 1}`: keys that are names).
  virtual std::vector<std::string> Keys() const;
  // "file:line:column" of the key itself, and of this entry (where its
  // mapping starts), for errors found after loading.
  virtual std::string WhereKey(std::string_view key) const;
  virtual std::string WhereHere() const;
};

// One world-file key of a type: its name, its default as the docs show it,
// and one line of documentation (worlds/README.md lists the same keys).
struct ObjectKey {
  const char* name;
  const char* default_text;
  const char* doc;
};

// State a ScaleSubtree call shares between the rows it scales: one scaled
// copy of each shared asset (a mesh) per call, so copies keep sharing.
struct ScaleContext {
  std::map<const void*, std::shared_ptr<const void>> assets;
};

struct ObjectTypeDescriptor {
  const char* name;         // "proximity_sensor": world files, messages, `swarmsim modules`
  const char* description;  // one line
  // What a type's hooks may need of their own (a plugin type's keys); the
  // hooks get their descriptor.
  const void* context = nullptr;
  // --- Rows ---------------------------------------------------------------------
  // A new, empty table of the type's rows; null for a type without rows (dummy).
  std::unique_ptr<RowTable> (*make_rows)(const ObjectTypeDescriptor& type) = nullptr;
  // Copy-paste of an object: the copy's row from the source's. Null: the
  // whole row (a force sensor copies its settings only and starts unbroken).
  void (*copy_row)(const void* source, void* row) = nullptr;
  // Size factor s (V-REP's): lengths x s, masses and forces x s^3, torques
  // x s^4. Null: nothing of the row scales.
  void (*scale_row)(const ObjectTypeDescriptor& type, void* row, double s,
                    ScaleContext* context) = nullptr;
  // --- State hash -------------------------------------------------------------------
  // Adds the rows' changing state (and each row's owner slot), in row order.
  // Null: the type adds nothing besides its objects' poses.
  void (*hash_rows)(const Scene& scene, ObjectType type, StateHasher* hasher) = nullptr;
  // --- World files ----------------------------------------------------------------
  // The keys an object of the type takes besides name, type, pose, script
  // and children, in the order messages list them.
  std::span<const ObjectKey> keys = {};
  // Fills `row` (a default row) from the object's entry.
  void (*read)(const ObjectTypeDescriptor& type, const ObjectReader& reader, void* row) = nullptr;
  // Once the whole world is built: throws swarmsim::Error (naming the file,
  // line and column the row kept) when the row names what the scene lacks,
  // such as a path that matches no object. Null: nothing to check.
  void (*check)(const Scene& scene, ObjectId id, const void* row) = nullptr;
  // --- Scripts -----------------------------------------------------------------------
  // The type's Lua API area: adds its sim.* functions to the table on top of
  // L's stack (framework/lua_api.h; sim.readProximitySensor, ...). Null: none.
  void (*register_lua)(lua_State* L) = nullptr;
  // --- Visuals ---------------------------------------------------------------------
  // What the object at `row` of the type looks like (framework/visual.h):
  // the recorder, the renderer and the viewer draw the type from this alone.
  // Fill *out (a default ObjectVisual) from the row and return; it runs for
  // every object of the type at every recorded step and rendered frame,
  // from several threads at once. Null (or kind kNone): not drawn, and
  // recorded only as a robot's root frame.
  void (*visual)(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) = nullptr;
  // --- Listing ---------------------------------------------------------------------
  // The name of a type this one is listed right after (world files' type
  // lists and their messages, and the order the state hash adds types in),
  // rather than after every type before it: a type that moved from the
  // built-in ones into its module keeps its place, so hashes and messages
  // stay (proximity_sensor: "joint"). Null, or a name not yet registered:
  // after the types before it.
  const char* listed_after = nullptr;
  // --- Links ----------------------------------------------------------------------
  // The objects the object at `row` was linked to at the last sense phase
  // (a range-and-bearing board: the boards it heard), appended to *out.
  // The recorder writes them at every recorded step (swarm/record/FORMAT.md,
  // "Links chunk") and the viewer draws a line for each, between recorded
  // objects (the object's type and the linked objects' types declare a
  // visual). Called between steps, on one thread. Null: no links.
  void (*links)(const Scene& scene, ObjectType type, uint32_t row,
                std::vector<ObjectId>* out) = nullptr;
  // --- Snapshots (framework/world_state.h) ---------------------------------------------
  // Writes the rows' changing state (what hash_rows adds, and what else of
  // it changes the future), in row order; load_rows reads it back into a
  // scene with the same rows (World::RestoreState checks that first). A
  // type with hash_rows and rows but no save_rows makes World::SaveState
  // refuse, naming the type. Null for both: nothing of the rows changes.
  void (*save_rows)(const Scene& scene, ObjectType type, StateWriter* out) = nullptr;
  void (*load_rows)(Scene* scene, ObjectType type, StateReader* in) = nullptr;
};

// The order `types` (by ObjectType value) are listed in: their indices,
// each type after the one its `listed_after` names, else in value order.
std::vector<size_t> ListingOrder(std::span<const ObjectTypeDescriptor* const> types);

// The built-in types, in the order world files, messages and the state hash
// list them (framework/types/core_types.cc).
std::span<const ObjectTypeDescriptor* const> CoreObjectTypes();

}  // namespace swarmsim
