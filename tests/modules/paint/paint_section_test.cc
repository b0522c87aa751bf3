// The paint module's world-file section `paint:` (paint_section.cc), read
// through the loader: it makes the world's floor layer (over the arena, or
// the area given), a world with nozzles gets one without the key, and its
// mistakes name file:line:column as the loader's own messages do.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "framework/floor_layer.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

class PaintSectionTest : public testing::WorldDirTest {
 protected:
  // The loader's message for `world_text`, or "(no error)".
  std::string ErrorOfWorld(const std::string& world_text) {
    try {
      Load(world_text);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
  void WriteBot(bool nozzle = false) {
    Write("bot.yaml", std::string("model: bot\nobjects:\n  type: shape\n  shape: box\n") +
                          "  size: [0.1, 0.1, 0.1]\n" +
                          (nozzle ? "  children: [{name: pen, type: paint_nozzle}]\n" : ""));
  }
};

void ExpectHas(const std::string& message, const std::vector<std::string>& fragments) {
  for (const std::string& fragment : fragments)
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "expected '" << fragment << "' in: " << message;
}

TEST_F(PaintSectionTest, PaintMakesTheWorldsFloorLayer) {
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\narena: {size: 2}\n"
      "paint: {resolution: 0.05, background: [0, 0, 0]}\n");
  const FloorLayer* floor = w.world->floor_layer();
  ASSERT_NE(floor, nullptr);
  const FloorArea area = floor->floor_area();
  EXPECT_EQ(area.width, 40);
  EXPECT_EQ(area.height, 40);
  EXPECT_DOUBLE_EQ(area.min_x, -1);
  EXPECT_DOUBLE_EQ(area.max_y, 1);
  EXPECT_EQ(floor->floor_rgb()[0], 0);
  // No `paint:` and no nozzle: no layer.
  EXPECT_EQ(Load("simulation: {physics: kinematic}\narena: {size: 2}\n").world->floor_layer(),
            nullptr);
  // Nozzles without `paint:`: the defaults over the arena.
  WriteBot(/*nozzle=*/true);
  LoadedWorld n = Load(
      "simulation: {physics: kinematic}\narena: {size: 1}\n"
      "models: [{model: bot.yaml, position: [0, 0]}]\n");
  ASSERT_NE(n.world->floor_layer(), nullptr);
  EXPECT_EQ(n.world->floor_layer()->floor_area().width, 100);
}

TEST_F(PaintSectionTest, PaintMistakesNameTheirPlace) {
  const std::string sim = "simulation: {physics: kinematic}\n";
  ExpectHas(
      ErrorOfWorld(sim + "arena: {size: 2}\npaint: [1]\n"),
      {"world.yaml:3:8:", "'paint' must be a mapping such as {resolution: 0.01} (got a list)"});
  ExpectHas(
      ErrorOfWorld(sim + "arena: {size: 2}\npaint: {resoluton: 0.1}\n"),
      {"world.yaml:3:9:", "unknown key 'resoluton' in 'paint'", "did you mean 'resolution'?"});
  ExpectHas(ErrorOfWorld(sim + "arena: {size: 2}\npaint: {area: {min: [1, 1], max: [0, 2]}}\n"),
            {"world.yaml:3:34:", "'area' needs max greater than min in x and in y"});
  ExpectHas(ErrorOfWorld(sim + "arena: {size: 2}\npaint: {area: 3}\n"),
            {"world.yaml:3:15:", "'area' must be {min: [x, y], max: [x, y]} (got"});
  ExpectHas(ErrorOfWorld(sim + "arena: {size: 2}\npaint: {area: {max: [1, 1]}}\n"),
            {"world.yaml:3:15:", "'min' is required in 'area'"});
  // Without an arena the layer needs an area: at `paint:`, or at the file
  // for a world whose nozzles ask for the layer.
  ExpectHas(ErrorOfWorld(sim + "paint: {resolution: 0.05}\n"),
            {"world.yaml:2:8:", "the paint layer (for paint nozzles) covers the arena"});
  WriteBot(/*nozzle=*/true);
  ExpectHas(ErrorOfWorld(sim + "models: [{model: bot.yaml, position: [0, 0]}]\n"),
            {"world.yaml:1:1:", "the paint layer (for paint nozzles) covers the arena"});
  ExpectHas(ErrorOfWorld(sim + "arena: {size: 2}\npaint: {resolution: 0.0001}\n"),
            {"world.yaml:3:8:", "over 100 megapixels"});
}

}  // namespace
}  // namespace swarmsim
