// Collections (framework/collections.cc; V-REP's collections): items added
// and removed in order, paths resolved from the collection object so that a
// collection inside a model is per copy, and entity paths for collision and
// distance objects.
#include "framework/collections.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "tests/framework/error_of.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;

CollectionItem Item(CollectionItemKind kind, std::string path, bool exclude = false,
                    std::string where = "") {
  return {kind, exclude, std::move(path), {}, std::move(where)};
}

// Walls /walls/{north, south} and robot bot#0 (/bot#0 with body, arm, tip
// under arm) whose collection `group` holds `items`.
struct Arena {
  explicit Arena(std::vector<CollectionItem> items) {
    walls = scene.AddDummy("walls", {}, {});
    north = scene.AddShape("north", walls, {}, {});
    south = scene.AddShape("south", walls, {}, {});
    bot = scene.AddDummy("bot#0", {}, {});
    body = scene.AddShape("body", bot, {}, {});
    arm = scene.AddDummy("arm", bot, {});
    tip = scene.AddDummy("tip", arm, {});
    CollectionRow row;
    row.items = std::move(items);
    group = scene.AddObject(ObjectType::kCollection, "group", bot, {}, &row);
    scene.MakeModelInstance(bot, "bot", "bot#0");
  }
  std::vector<uint32_t> Slots(std::initializer_list<ObjectId> ids) const {
    std::vector<uint32_t> out;
    for (ObjectId id : ids) out.push_back(id.index());
    std::sort(out.begin(), out.end());
    return out;
  }
  Scene scene;
  ObjectId walls, north, south, bot, body, arm, tip, group;
};

TEST(CollectionsTest, ItemsAddAndRemoveInOrderAndACollectionIsNeverItsOwnMember) {
  // This model copy, but the arm alone (its tip stays).
  Arena a({Item(CollectionItemKind::kTree, ":"),
           Item(CollectionItemKind::kObject, ":/arm", /*exclude=*/true)});
  EXPECT_EQ(CollectionSlots(a.scene, a.group), a.Slots({a.bot, a.body, a.tip}));
  // Everything but the walls' tree.
  Arena b({Item(CollectionItemKind::kAll, ""),
           Item(CollectionItemKind::kTree, "/walls", /*exclude=*/true)});
  EXPECT_EQ(CollectionSlots(b.scene, b.group), b.Slots({b.bot, b.body, b.arm, b.tip}));
  // Order matters: a tree removed, then one of its objects added back.
  Arena d({Item(CollectionItemKind::kTree, "/walls", true),
           Item(CollectionItemKind::kObject, "/walls/south")});
  EXPECT_EQ(CollectionSlots(d.scene, d.group), d.Slots({d.south}));
}

TEST(CollectionsTest, ACollectionInAModelNamesTheObjectsOfItsOwnCopy) {
  Arena a({Item(CollectionItemKind::kTree, ":/arm")});
  const ObjectId copy = a.scene.DuplicateSubtree(a.bot, {});
  const ObjectId copy_group = a.scene.FindObject("./group", copy);
  ASSERT_FALSE(copy_group.IsNull());
  const ObjectId copy_arm = a.scene.FindObject("./arm", copy);
  const ObjectId copy_tip = a.scene.FindObject("./arm/tip", copy);
  EXPECT_EQ(CollectionSlots(a.scene, copy_group), a.Slots({copy_arm, copy_tip}));
  EXPECT_EQ(CollectionSlots(a.scene, a.group), a.Slots({a.arm, a.tip}));
  // Removing the copy removes its collection with it.
  a.scene.RemoveSubtree(copy);
  EXPECT_FALSE(a.scene.IsValid(copy_group));
  EXPECT_EQ(CollectionSlots(a.scene, a.group), a.Slots({a.arm, a.tip}));
}

TEST(CollectionsTest, AnItemThatMatchesNothingNamesItsFileLineAndTheCollection) {
  Arena a({Item(CollectionItemKind::kTree, ":/amr", false, "bot.yaml:12:14")});
  EXPECT_CONTAINS(ErrorOf([&] { CollectionSlots(a.scene, a.group); }),
                  "bot.yaml:12:14: collection /bot#0/group: item ':/amr' matches no object");
  // A script's item by handle whose object was removed.
  Arena b({});
  CollectionItem by_handle;
  by_handle.kind = CollectionItemKind::kObject;
  by_handle.id = b.tip;
  b.scene.RemoveSubtree(b.tip);
  EXPECT_EQ(ErrorOf([&] {
              CollectionSlots(b.scene, std::vector<CollectionItem>{by_handle}, {}, "my set");
            }),
            "my set: an item's object was removed (stale handle)");
  EXPECT_EQ(ErrorOf([&] { CollectionSlots(b.scene, b.arm); }),
            "object /bot#0/arm is not a collection");
}

TEST(CollectionsTest, EntitiesAreKeywordsOrPaths) {
  EXPECT_EQ(ParseEntity("environment").kind, EntitySpec::kEnvironment);
  EXPECT_EQ(ParseEntity("everything_else").kind, EntitySpec::kEverythingElse);
  const EntitySpec path = ParseEntity("/bot#0/arm");
  EXPECT_EQ(path.kind, EntitySpec::kPath);
  EXPECT_EQ(path.path, "/bot#0/arm");
  EXPECT_EQ(ParseEntity("Environment").kind, EntitySpec::kPath);  // names are exact
}

TEST(CollectionsTest, AnEntityPathIsACollectionsObjectsOrAnObjectsTree) {
  Arena a({Item(CollectionItemKind::kObject, "/walls/north"),
           Item(CollectionItemKind::kObject, ":/body")});
  EXPECT_EQ(EntitySlots(a.scene, "/bot#0/group", {}, "collision 'c'"), a.Slots({a.north, a.body}));
  EXPECT_EQ(EntitySlots(a.scene, "/bot#0/arm", {}, "collision 'c'"), a.Slots({a.arm, a.tip}));
  EXPECT_EQ(EntitySlots(a.scene, ":/arm", a.body, "collision 'c'"), a.Slots({a.arm, a.tip}));
  EXPECT_CONTAINS(ErrorOf([&] { EntitySlots(a.scene, "/bot#0/leg", {}, "collision 'c'"); }),
                  "collision 'c': '/bot#0/leg' matches no object");
}

}  // namespace
}  // namespace swarmsim
