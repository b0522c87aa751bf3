// collection: a named group of objects (V-REP's collections;
// framework/collections.h). Items, in this order: `all`, then `trees` and
// `objects` added, then `exclude_trees` and `exclude_objects` removed.
#include <string>
#include <vector>

#include "framework/collections.h"
#include "framework/object_type.h"
#include "framework/types/core_types.h"

namespace swarmsim {

// Its Lua API area (framework/lua_api_collections.cc).
void RegisterCollectionsApi(lua_State* L);

namespace {

constexpr size_t kMaxItems = 10000;

constexpr ObjectKey kKeys[] = {
    {"all", "false", "start from every object of the scene"},
    {"trees", "[]", "paths of objects added with everything below them (\":\": this model copy)"},
    {"objects", "[]", "paths of objects added alone"},
    {"exclude_trees", "[]", "paths of objects removed with everything below them"},
    {"exclude_objects", "[]", "paths of objects removed alone"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<CollectionRow>>();
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  std::vector<CollectionItem>& items = static_cast<CollectionRow*>(row)->items;
  if (r.Has("all") && r.Bool("all")) items.push_back({CollectionItemKind::kAll, false, "", {}, ""});
  const auto add = [&](const char* key, CollectionItemKind kind, bool exclude) {
    if (!r.Has(key)) return;
    for (std::string& path : r.Strings(key, kMaxItems)) {
      if (path.empty() || (path[0] != '/' && path[0] != ':' && path[0] != '.'))
        r.Fail(key, "'" + path +
                        "' is not an object path: start with '/' (absolute), ':' (this model) "
                        "or './' (below the collection)");
      items.push_back({kind, exclude, std::move(path), {}, r.Where(key)});
    }
  };
  add("trees", CollectionItemKind::kTree, false);
  add("objects", CollectionItemKind::kObject, false);
  add("exclude_trees", CollectionItemKind::kTree, true);
  add("exclude_objects", CollectionItemKind::kObject, true);
  if (items.empty())
    r.FailAtKey("name", "a collection needs at least one of 'all', 'trees' or 'objects'");
}

// Every item's path matches an object.
void Check(const Scene& scene, ObjectId id, const void*) { CollectionSlots(scene, id); }

}  // namespace

const ObjectTypeDescriptor kCollectionType{
    .name = "collection",
    .description = "a named group of objects, for collision and distance objects and sensors",
    .make_rows = MakeRows,
    .keys = kKeys,
    .read = Read,
    .check = Check,
    .register_lua = RegisterCollectionsApi,
};

}  // namespace swarmsim
