// worlds/ground_nest.yaml: foot-bots wander over a floor (a PNG image with a
// black nest drawn on it) and stop, LED red, once their ground sensors have
// all read the nest for a while. By the end most robots are home, every
// robot that says so stands on the nest, none does in the same world
// without a nest, and the run is the same at 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

constexpr double kNestX = 1, kNestY = 1;  // the nest's centre in the world file

struct Outcome {
  int robots = 0, home = 0, home_off_nest = 0;
  uint64_t hash = 0;
};

Outcome RunNest(int threads, int64_t steps, const std::string& nest_radius = "") {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions options;
  options.threads = threads;
  if (!nest_radius.empty()) options.overrides.push_back({"nest_radius", nest_radius});
  LoadedWorld w =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/ground_nest.yaml", options, registry);
  w.world->set_log_sink([](std::string_view) {});
  EXPECT_EQ(w.steps, 6000);
  w.world->Start();
  for (int64_t s = 0; s < steps; ++s) w.world->Step();
  Outcome out;
  const Scene& scene = w.world->scene();
  ObjectType led_type;
  EXPECT_TRUE(scene.FindType(kLedTypeName, &led_type));
  const double radius = nest_radius.empty() ? 0.6 : std::stod(nest_radius);
  for (const ModelInstance& robot : scene.instances()) {
    ++out.robots;
    const LedRow& led = scene.row<LedRow>(led_type, scene.FindObject("./led", robot.root), "led");
    const bool red = led.color.x == 1 && led.color.y == 0 && led.color.z == 0;
    if (!red) {
      EXPECT_EQ(led.color.y, 1) << robot.name << ": an LED neither green nor red";
      continue;
    }
    ++out.home;
    // Its 4 sensors (6.4 cm from its centre, around it) all read the nest:
    // its centre is on the nest, to within a floor pixel (1 cm).
    const Vec3 p = scene.world_pose(robot.root).p;
    if (std::hypot(p.x - kNestX, p.y - kNestY) > radius + 0.01) ++out.home_off_nest;
  }
  out.hash = w.world->StateHash();
  return out;
}

TEST(GroundNestTest, MostRobotsFindTheNestAndStopOnIt) {
  const Outcome nest = RunNest(1, 6000);
  EXPECT_EQ(nest.robots, 20);
  EXPECT_GE(nest.home, 10) << "fewer than half the robots home after 10 minutes";
  EXPECT_EQ(nest.home_off_nest, 0);
  // The same floor without the nest (radius 0: the circle draws nothing; the
  // grey halo is lighter than nest_grey): nobody stops.
  const Outcome none = RunNest(1, 6000, "0");
  EXPECT_EQ(none.home, 0);
}

TEST(GroundNestTest, OneAndTwoThreadsGiveTheSameRun) {
  const Outcome one = RunNest(1, 1500);
  const Outcome two = RunNest(2, 1500);
  EXPECT_EQ(one.hash, two.hash);
  EXPECT_EQ(one.home, two.home);
  EXPECT_GE(one.home, 1);  // the run got as far as someone finding the nest
}

}  // namespace
}  // namespace swarmsim
