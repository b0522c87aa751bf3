#include "framework/collections.h"

#include <algorithm>

#include "framework/error.h"
#include "framework/scene.h"

namespace swarmsim {

namespace {

ObjectId Resolve(const Scene& scene, const CollectionItem& item, ObjectId from,
                 std::string_view what, Missing missing) {
  if (item.path.empty()) {
    if (!scene.IsValid(item.id)) {
      if (missing == Missing::kNone) return {};
      throw Error(std::string(what) + ": an item's object was removed (stale handle)");
    }
    return item.id;
  }
  const ObjectId id = scene.FindObject(item.path, from);
  if (id.IsNull() && missing == Missing::kError)
    throw Error((item.where.empty() ? "" : item.where + ": ") + std::string(what) + ": item '" +
                item.path + "' matches no object" + scene.ExplainMissingPath(item.path, from));
  return id;
}

}  // namespace

std::vector<uint32_t> CollectionSlots(const Scene& scene, std::span<const CollectionItem> items,
                                      ObjectId from, std::string_view what, Missing missing) {
  std::vector<char> in(scene.slot_count(), 0);
  std::vector<uint32_t> subtree;
  for (const CollectionItem& item : items) {
    const char mark = item.exclude ? 0 : 1;
    if (item.kind == CollectionItemKind::kAll) {
      for (uint32_t s = 0; s < scene.slot_count(); ++s)
        if (scene.alive_at(s)) in[s] = mark;
      continue;
    }
    const ObjectId id = Resolve(scene, item, from, what, missing);
    if (id.IsNull()) continue;  // Missing::kNone: a removed robot's
    subtree.clear();
    if (item.kind == CollectionItemKind::kTree)
      scene.CollectSubtree(id.index(), &subtree);
    else
      subtree.push_back(id.index());
    for (uint32_t s : subtree) in[s] = mark;
  }
  std::vector<uint32_t> out;
  for (uint32_t s = 0; s < in.size(); ++s)
    if (in[s] && scene.type_at(s) != ObjectType::kCollection) out.push_back(s);
  return out;
}

std::vector<uint32_t> CollectionSlots(const Scene& scene, ObjectId collection, Missing missing) {
  const uint32_t slot = scene.SlotOf(collection, "collection");
  if (scene.type_at(slot) != ObjectType::kCollection)
    throw Error("object " + scene.PathOf(collection) + " is not a collection");
  const auto& rows = static_cast<const Rows<CollectionRow>&>(*scene.rows(ObjectType::kCollection));
  return CollectionSlots(scene, rows.rows[scene.row_at(slot)].items, collection,
                         "collection " + scene.PathOf(collection), missing);
}

EntitySpec ParseEntity(std::string_view text) {
  if (text == "environment") return {EntitySpec::kEnvironment, ""};
  if (text == "everything_else") return {EntitySpec::kEverythingElse, ""};
  return {EntitySpec::kPath, std::string(text)};
}

std::vector<uint32_t> EntitySlots(const Scene& scene, std::string_view path, ObjectId from,
                                  std::string_view what, Missing missing) {
  const ObjectId id = scene.FindObject(path, from);
  if (id.IsNull() && missing == Missing::kNone) return {};
  if (id.IsNull())
    throw Error(std::string(what) + ": '" + std::string(path) + "' matches no object" +
                scene.ExplainMissingPath(path, from));
  if (scene.type(id) == ObjectType::kCollection) return CollectionSlots(scene, id, missing);
  std::vector<uint32_t> out;
  scene.CollectSubtree(id.index(), &out);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace swarmsim
