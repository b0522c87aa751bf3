// sim.* collections (framework/collections.h): a script's own collections,
// and the objects of any collection.
//
// A script's collections (sim.createCollection) belong to its robot (the
// RobotRuntime), not to the scene: scripts of many robots run at once, and
// the scene's tree changes only between phases. Their handles are
// kScriptCollectionBase - k, numbered per robot, and go with the robot.
#include <algorithm>
#include <string>
#include <vector>

#include "framework/collections.h"
#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/world.h"

namespace swarmsim {

namespace {

constexpr lua_Integer kHandleAll = -2;
constexpr lua_Integer kHandleSingle = -3;
constexpr lua_Integer kHandleTree = -4;
constexpr size_t kMaxScriptCollections = 10000;

std::vector<CollectionRow>& ScriptCollections(lua_State* L) {
  RobotRuntime* runtime = Context(L).runtime;
  if (runtime == nullptr) throw Error("no robot to hold the collection");
  return runtime->collections.get();
}

CollectionRow& ScriptCollection(lua_State* L, lua_Integer handle) {
  std::vector<CollectionRow>& all = ScriptCollections(L);
  // Unsigned: kScriptCollectionBase - math.maxinteger overflowed (undefined).
  const uint64_t k = static_cast<uint64_t>(kScriptCollectionBase) - static_cast<uint64_t>(handle);
  if (handle > kScriptCollectionBase || k >= all.size())
    throw Error("handle " + std::to_string(handle) +
                " is not a collection of this script's robot (sim.createCollection makes one)");
  return all[static_cast<size_t>(k)];
}

// sim.createCollection() -> handle of a new, empty collection of the robot's.
int CreateCollection(lua_State* L) {
  std::vector<CollectionRow>& all = ScriptCollections(L);
  if (all.size() >= kMaxScriptCollections)
    throw Error("a robot may make at most " + std::to_string(kMaxScriptCollections) +
                " collections");
  ChargeScriptData(L, sizeof(CollectionRow), "the collection");  // for the robot's lifetime
  Context(L).runtime->lifetime_bytes += sizeof(CollectionRow);
  all.emplace_back();
  lua_pushinteger(L, kScriptCollectionBase - static_cast<lua_Integer>(all.size() - 1));
  return 1;
}

// sim.addItemToCollection(h, what, object [, options]): what is
// sim.handle_single (the object), sim.handle_tree (it and everything below
// it) or sim.handle_all (every object; `object` is ignored); options bit 0
// removes the objects instead.
int AddItemToCollection(lua_State* L) {
  const lua_Integer handle = ArgInteger(L, 1);
  const Scene& scene = *Context(L).scene;
  if (handle > 0 && scene.IsValid(ObjectId::FromInteger(handle))) {
    const ObjectId id = ObjectId::FromInteger(handle);
    if (scene.type(id) != ObjectType::kCollection)
      throw Error(scene.PathOf(id) + " is not a collection (sim.createCollection makes one)");
    throw Error("collection " + scene.PathOf(id) +
                " comes from a model or world file and cannot change; make one with "
                "sim.createCollection");
  }
  CollectionRow& collection = ScriptCollection(L, handle);
  const lua_Integer what = ArgInteger(L, 2);
  CollectionItem item;
  if (what == kHandleAll) {
    item.kind = CollectionItemKind::kAll;
  } else if (what == kHandleSingle || what == kHandleTree) {
    item.kind = what == kHandleTree ? CollectionItemKind::kTree : CollectionItemKind::kObject;
    item.id = CheckObject(L, 3);
    scene.SlotOf(item.id);  // throws for a stale handle
  } else {
    throw Error("bad argument #2 (sim.handle_single, sim.handle_tree or sim.handle_all expected)");
  }
  item.exclude = !lua_isnoneornil(L, 4) && (ArgInteger(L, 4) & 1) != 0;
  ChargeScriptData(L, sizeof(CollectionItem), "the collection item");
  Context(L).runtime->lifetime_bytes += sizeof(CollectionItem);
  collection.items.push_back(item);
  return 0;
}

// sim.getCollectionObjects(h) -> the handles of the collection's objects,
// in scene order.
int GetCollectionObjects(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  const std::vector<uint32_t> slots = CollectionArgSlots(L, 1);
  lua_createtable(L, static_cast<int>(slots.size()), 0);
  for (size_t i = 0; i < slots.size(); ++i) {
    lua_pushinteger(L, scene.IdAt(slots[i]).ToInteger());
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  return 1;
}

}  // namespace

std::vector<uint32_t> CollectionArgSlots(lua_State* L, int arg) {
  const lua_Integer handle = ArgInteger(L, arg);
  const Scene& scene = *Context(L).scene;
  if (handle <= kScriptCollectionBase)
    return CollectionSlots(scene, ScriptCollection(L, handle).items, {}, "the collection",
                           Missing::kNone);
  const ObjectId id = ObjectId::FromInteger(handle);
  const uint32_t slot = scene.SlotOf(id);
  if (scene.type_at(slot) == ObjectType::kCollection)
    return CollectionSlots(scene, id, Missing::kNone);  // a removed robot's items: none
  std::vector<uint32_t> out;
  scene.CollectSubtree(slot, &out);
  std::sort(out.begin(), out.end());
  return out;
}

void RegisterCollectionsApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"createCollection", Guarded<CreateCollection, "sim.createCollection">},
      {"addItemToCollection", Guarded<AddItemToCollection, "sim.addItemToCollection">},
      {"getCollectionObjects", Guarded<GetCollectionObjects, "sim.getCollectionObjects">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
  lua_pushinteger(L, kHandleAll);
  lua_setfield(L, -2, "handle_all");
  lua_pushinteger(L, kHandleSingle);
  lua_setfield(L, -2, "handle_single");
  lua_pushinteger(L, kHandleTree);
  lua_setfield(L, -2, "handle_tree");
}

}  // namespace swarmsim
