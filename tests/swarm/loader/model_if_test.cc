// `if:` on a model's objects (worlds/README.md, "Objects"): an object whose
// `if` is false is left out with its subtree (a ring or ground array: all
// its sensors), one whose `if` is true is there; parameters and expressions
// decide it; the root cannot have one; mistakes inside an object left out
// are still errors.
#include <gtest/gtest.h>

#include <string>

#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

class ModelIfTest : public testing::WorldDirTest {
 protected:
  // A model with a parameter `a` (default false) and `b` (default true), and
  // objects guarded by them; placed once with `parameters`.
  LoadedWorld LoadBot(const std::string& parameters) {
    Write("bot.yaml",
          "model: bot\n"
          "parameters: {a: false, b: true}\n"
          "objects:\n"
          "  name: body\n"
          "  type: shape\n"
          "  shape: cylinder\n"
          "  radius: 0.1\n"
          "  height: 0.1\n"
          "  children:\n"
          "    - {if: $a, name: x, type: dummy, children: [{name: x_child, type: dummy}]}\n"
          "    - {if: $b, name: y, type: dummy}\n"
          "    - {if: \"= a or not b\", type: proximity_ring, name: ring, count: 4, radius: 0.1}\n"
          "    - {if: $a, type: ground_array, name: g, points: [[0, 0], [0.1, 0]]}\n");
    return Load(
        "simulation: {physics: kinematic}\nmodels: [{model: bot.yaml, position: [0, 0], "
        "parameters: {" +
        parameters + "}}]\n");
  }
  static bool Has(LoadedWorld& w, const std::string& path) {
    return !w.world->scene().FindObject(path).IsNull();
  }
};

TEST_F(ModelIfTest, ObjectsWhoseIfIsFalseAreLeftOutWithTheirSubtrees) {
  LoadedWorld defaults = LoadBot("");
  EXPECT_FALSE(Has(defaults, "/bot#0/x"));
  EXPECT_FALSE(Has(defaults, "/bot#0/x/x_child"));
  EXPECT_TRUE(Has(defaults, "/bot#0/y"));
  EXPECT_FALSE(Has(defaults, "/bot#0/ring[0]"));
  EXPECT_FALSE(Has(defaults, "/bot#0/g[0]"));
  EXPECT_EQ(defaults.world->scene().object_count(), 2u);  // body and y

  LoadedWorld all = LoadBot("a: true");
  EXPECT_TRUE(Has(all, "/bot#0/x"));
  EXPECT_TRUE(Has(all, "/bot#0/x/x_child"));
  EXPECT_TRUE(Has(all, "/bot#0/ring[3]"));
  EXPECT_TRUE(Has(all, "/bot#0/g[1]"));
  EXPECT_EQ(all.world->scene().object_count(), 2u + 2 + 4 + 2);

  LoadedWorld expression = LoadBot("b: false");  // "= a or not b"
  EXPECT_TRUE(Has(expression, "/bot#0/ring[0]"));
  EXPECT_FALSE(Has(expression, "/bot#0/y"));
}

TEST_F(ModelIfTest, MistakesAreErrorsEvenInObjectsLeftOut) {
  Write("bot.yaml",
        "model: bot\nobjects:\n  name: body\n  type: dummy\n  children:\n"
        "    - {if: false, name: x, type: dummy, raduis: 1}\n");
  EXPECT_CONTAINS(
      testing::ErrorOf([&] { Load("models: [{model: bot.yaml, position: [0, 0]}]\n"); }),
      "bot.yaml:6:");
  Write("bot.yaml",
        "model: bot\nobjects:\n  name: body\n  type: dummy\n  children:\n"
        "    - {if: maybe, name: x, type: dummy}\n");
  EXPECT_CONTAINS(
      testing::ErrorOf([&] { Load("models: [{model: bot.yaml, position: [0, 0]}]\n"); }),
      "bot.yaml:6:");
  Write("bot.yaml", "model: bot\nobjects:\n  if: true\n  name: body\n  type: dummy\n");
  EXPECT_CONTAINS(
      testing::ErrorOf([&] { Load("models: [{model: bot.yaml, position: [0, 0]}]\n"); }),
      "the root object of a model cannot have 'if'");
}

}  // namespace
}  // namespace swarmsim
