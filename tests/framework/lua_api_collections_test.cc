// sim.* collections (framework/lua_api_collections.cc): a script's own
// collections, numbered per robot, and the objects of any collection.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/collections.h"
#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;

// A world with null modules whose script output lands in `log`.
class ScriptWorld {
 public:
  ScriptWorld() : registry_(testing::NullRegistry()) {
    WorldSettings settings;
    settings.physics = "null";
    settings.time_step = 0.1;
    settings.threads = 1;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
  }
  Scene& scene() { return world_->scene(); }
  // Robot `name`: a root dummy with `body` (carrying `code`), `arm` and
  // `arm/tip`.
  ObjectId AddRobot(const std::string& name, const std::string& code) {
    const ObjectId root = scene().AddDummy(name, {}, {});
    const ObjectId body = scene().AddDummy("body", root, {});
    const ObjectId arm = scene().AddDummy("arm", root, {});
    scene().AddDummy("tip", arm, {});
    scene().MakeModelInstance(root, "bot", name);
    scene().AttachScript(
        body, std::make_shared<const ScriptSource>(ScriptSource{"scripts/robot.lua", code}));
    return root;
  }
  std::string Step() {
    return ErrorOf([&] { world_->Step(); });
  }
  std::vector<std::string> log;

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
};

// Prints the names of the objects of collection `h`.
constexpr const char* kPrintNames = R"(
  function names(h)
    local out = {}
    for i, o in ipairs(sim.getCollectionObjects(h)) do out[i] = sim.getObjectName(o) end
    return table.concat(out, ' ')
  end
)";

TEST(LuaApiCollectionsTest, AScriptBuildsACollectionItemByItem) {
  ScriptWorld w;
  w.AddRobot("bot#0", std::string(kPrintNames) + R"(
    function sysCall_init()
      local c = sim.createCollection()
      print(c, #sim.getCollectionObjects(c))
      sim.addItemToCollection(c, sim.handle_tree, sim.getObject(':'))
      print(names(c))
      sim.addItemToCollection(c, sim.handle_single, sim.getObject(':/arm'), 1)
      print(names(c))
      local d = sim.createCollection()
      sim.addItemToCollection(d, sim.handle_all, -1)
      sim.addItemToCollection(d, sim.handle_tree, sim.getObject(':'), 1)
      print(d, names(d))
      -- Any object's handle stands for it and everything below it.
      print(names(sim.getObject(':/arm')))
    end
  )");
  w.scene().AddDummy("post", {}, {});
  EXPECT_EQ(w.Step(), "");
  const std::vector<std::string> expected = {"[bot#0] -1000\t0", "[bot#0] bot#0 body arm tip",
                                             "[bot#0] bot#0 body tip", "[bot#0] -1001\tpost",
                                             "[bot#0] arm tip"};
  EXPECT_EQ(w.log, expected);
}

// Handles count from -1000 for each robot: robot 1's first collection is
// -1000 too, and robot 0's -1000 is not robot 1's.
TEST(LuaApiCollectionsTest, EachRobotHasItsOwnCollections) {
  ScriptWorld w;
  for (const char* name : {"bot#0", "bot#1"})
    w.AddRobot(name, std::string(kPrintNames) + R"(
      function sysCall_init()
        c = sim.createCollection()
        sim.addItemToCollection(c, sim.handle_single, sim.getObject(':/arm'))
      end
      function sysCall_actuation()
        print(c, sim.getObjectName(sim.getObjectParent(sim.getCollectionObjects(c)[1])),
              sim.getCollectionObjects(c)[1] == sim.getObject(':/arm'))
      end
    )");
  EXPECT_EQ(w.Step(), "");
  const std::vector<std::string> expected = {"[bot#0] -1000\tbot#0\ttrue",
                                             "[bot#1] -1000\tbot#1\ttrue"};
  EXPECT_EQ(w.log, expected);
}

TEST(LuaApiCollectionsTest, AWorldFilesCollectionIsReadOnlyAndMistakesAreErrors) {
  const std::pair<std::string, std::string> cases[] = {
      {"sim.addItemToCollection(sim.getObject('/bot#0/group'), sim.handle_all, -1)",
       "sim.addItemToCollection: collection /bot#0/group comes from a model or world file and "
       "cannot change; make one with sim.createCollection"},
      {"sim.addItemToCollection(sim.getObject(':/arm'), sim.handle_all, -1)",
       "sim.addItemToCollection: /bot#0/arm is not a collection (sim.createCollection makes "
       "one)"},
      {"sim.addItemToCollection(-1000, sim.handle_all, -1)",
       "sim.addItemToCollection: handle -1000 is not a collection of this script's robot "
       "(sim.createCollection makes one)"},
      {"sim.addItemToCollection(sim.createCollection(), 7, -1)",
       "sim.addItemToCollection: bad argument #2 (sim.handle_single, sim.handle_tree or "
       "sim.handle_all expected)"},
      {"sim.getCollectionObjects(-1005)",
       "sim.getCollectionObjects: handle -1005 is not a collection of this script's robot"},
      // The extremes: -1000 - math.maxinteger overflowed (undefined behaviour;
      // the sanitizer preset's UBSan names it).
      {"sim.addItemToCollection(math.maxinteger, sim.handle_all, -1)",
       "sim.addItemToCollection: handle 9223372036854775807 is not a collection of this "
       "script's robot"},
      {"sim.getCollectionObjects(math.mininteger)",
       "sim.getCollectionObjects: handle -9223372036854775808 is not a collection of this "
       "script's robot"},
  };
  for (const auto& [call, message] : cases) {
    ScriptWorld w;
    const ObjectId root = w.AddRobot("bot#0", "function sysCall_init()\n  " + call + "\nend");
    CollectionRow row;
    row.items.push_back({CollectionItemKind::kTree, false, ":/arm", {}, ""});
    w.scene().AddObject(ObjectType::kCollection, "group", root, {}, &row);
    EXPECT_CONTAINS(w.Step(), "bot#0: scripts/robot.lua:2: " + message);
  }
}

// A world file's collection reads the same from Lua as from C++.
TEST(LuaApiCollectionsTest, AWorldFilesCollectionListsItsObjects) {
  ScriptWorld w;
  const ObjectId root = w.AddRobot("bot#0", std::string(kPrintNames) + R"(
    function sysCall_init() print(names(sim.getObject(':/group'))) end
  )");
  CollectionRow row;
  row.items.push_back({CollectionItemKind::kTree, false, ":", {}, ""});
  row.items.push_back({CollectionItemKind::kObject, true, ":/body", {}, ""});
  w.scene().AddObject(ObjectType::kCollection, "group", root, {}, &row);
  EXPECT_EQ(w.Step(), "");
  EXPECT_EQ(w.log, std::vector<std::string>{"[bot#0] bot#0 arm tip"});
}

}  // namespace
}  // namespace swarmsim
