// The scripts' side of modules/collision (lua_api_collision.cc):
// sim.checkDistance, sim.checkCollision, sim.readDistance,
// sim.readCollision, and their errors.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "modules/collision/rows.h"
#include "tests/modules/module_world.h"

namespace swarmsim::collision {
namespace {

using testing::ModuleWorld;

// A distance or collision row between entities a and b.
template <typename Row>
Row Between(std::string a, std::string b) {
  Row row;
  row.entity[0] = std::move(a);
  row.entity[1] = std::move(b);
  return row;
}

// Unit cubes /a at the origin, /b at x = 3 and /c overlapping a (at x =
// 0.9); a distance object /gap between a and b; `code` runs on /a.
struct CollisionScripts {
  ModuleWorld w;
  explicit CollisionScripts(const std::string& code) {
    const ObjectId a = w.Box("a", {}, {}, {1, 1, 1});
    w.Box("b", {}, {{3, 0, 0}, {}}, {1, 1, 1});
    w.Box("c", {}, {{0.9, 0, 0}, {}}, {1, 1, 1});
    const auto d = Between<DistanceRow>("/a", "/b");
    w.Add("distance", "gap", {}, {}, &d);
    const auto c = Between<CollisionRow>("/a", "/c");
    w.Add("collision", "touch", {}, {}, &c);
    w.Script(a, code);
  }
  std::string Log() const {
    std::string all;
    for (const std::string& line : w.log()) all += line + "\n";
    return all;
  }
};

TEST(LuaApiCollisionTest, ScriptsCheckAndReadDistancesAndCollisions) {
  CollisionScripts s(R"(
    function sysCall_sensing()
      local a, b, c = sim.getObject('/a'), sim.getObject('/b'), sim.getObject('/c')
      local found, data, pair = sim.checkDistance(a, b)
      print(string.format('check %d d=%.6f x1=%.6f x2=%.6f a=%s b=%s', found, data[7], data[1],
                          data[4], tostring(pair[1] == a), tostring(pair[2] == b)))
      local near = sim.checkDistance(a, b, 1.5)
      print(string.format('within 1.5: %d', near))
      local hit, shapes = sim.checkCollision(a, c)
      print(string.format('collide %d %s', hit, tostring(shapes[1] == a and shapes[2] == c)))
      print(string.format('apart %d', (sim.checkCollision(a, b))))
      local d, points = sim.readDistance(sim.getObject('/gap'))
      print(string.format('read %.6f %.6f', d, points[4]))
      local colliding = sim.readCollision(sim.getObject('/touch'))
      print(string.format('touch %d', colliding))
    end
  )");
  ASSERT_EQ(s.w.Run(1), "");
  const std::string log = s.Log();
  EXPECT_CONTAINS(log, "check 1 d=2.000000 x1=0.500000 x2=2.500000 a=true b=true");
  EXPECT_CONTAINS(log, "within 1.5: 0");
  EXPECT_CONTAINS(log, "collide 1 true");
  EXPECT_CONTAINS(log, "apart 0");
  EXPECT_CONTAINS(log, "read 2.000000 2.500000");
  EXPECT_CONTAINS(log, "touch 1");
}

// A distance object with nothing within its threshold reads nil.
TEST(LuaApiCollisionTest, ADistanceWithNothingFoundReadsNil) {
  ModuleWorld w;
  const ObjectId a = w.Box("a", {}, {}, {1, 1, 1});
  w.Box("b", {}, {{3, 0, 0}, {}}, {1, 1, 1});
  auto d = Between<DistanceRow>("/a", "/b");
  d.threshold = 1;
  w.Add("distance", "gap", {}, {}, &d);
  w.Script(a,
           "function sysCall_sensing()\n"
           "  print('nil? ' .. tostring(sim.readDistance(sim.getObject('/gap')) == nil))\n"
           "end\n");
  ASSERT_EQ(w.Run(1), "");
  ASSERT_FALSE(w.log().empty());
  EXPECT_CONTAINS(w.log().back(), "nil? true");
}

std::string ErrorOfLine(const std::string& line) {
  CollisionScripts s("function sysCall_init()\n" + line + "\nend\n");
  return s.w.Run(1);
}

TEST(LuaApiCollisionTest, MistakesAreErrorsNamingWhatIsWrong) {
  EXPECT_CONTAINS(ErrorOfLine("sim.checkDistance(sim.getObject('/a'), 'wall')"),
                  "bad argument #2 ('environment', 'everything_else' or a handle expected, got "
                  "'wall')");
  EXPECT_CONTAINS(ErrorOfLine("sim.checkDistance(sim.getObject('/a'), sim.getObject('/a'))"),
                  "the two entities are the same objects: nothing to measure between them");
  EXPECT_CONTAINS(ErrorOfLine("sim.checkDistance(sim.getObject('/a'), sim.getObject('/b'), 0)"),
                  "bad argument #3 (a positive threshold expected)");
  EXPECT_CONTAINS(ErrorOfLine("sim.readDistance(sim.getObject('/touch'))"),
                  "object /touch is not a distance object");
  EXPECT_CONTAINS(ErrorOfLine("sim.readCollision(sim.getObject('/gap'))"),
                  "object /gap is not a collision object");
}

}  // namespace
}  // namespace swarmsim::collision
