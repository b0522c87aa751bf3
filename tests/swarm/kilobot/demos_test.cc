// The Kilobot demonstrations and experiments (worlds/kilobot/*.c, written
// from kilolib's documentation, built into build/plugins/kilobot_*.so) do
// what their documentation says, on worlds/models/kilobot.yaml robots with
// their IR transceivers: the gradient equals the hop count, the orbiting
// robot keeps its distance while it goes round, blinks synchronise, a packed
// swarm disperses, the edge follower goes round the group at its distance,
// and best-of-n reaches consensus on the better option (the other one when
// the qualities are swapped).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

std::string WorldFile(const std::string& name) {
  return std::string(SWARMSIM_SOURCE_DIR) + "/worlds/" + name;
}

LoadedWorld Load(const std::string& world, int threads = 1,
                 std::map<std::string, std::string> set = {},
                 std::vector<fs::path> plugin_dirs = {}) {
  static ModuleRegistry registry = [] {
    ModuleRegistry r;
    RegisterBuiltinModules(&r);
    return r;
  }();
  LoadOptions options;
  options.threads = threads;
  for (auto& [k, v] : set) options.overrides.push_back({k, v});
  plugin_dirs.push_back(fs::path(SWARMSIM_BINARY).parent_path() / "plugins");
  options.plugin_directories = plugin_dirs;
  LoadedWorld w = LoadWorld(WorldFile(world), options, registry);
  w.world->set_log_sink([](std::string_view) {});
  return w;
}

Vec3 Position(const Scene& scene, int robot) {
  return scene.world_pose(scene.instance(robot).root).p;
}

const LedRow& Led(const Scene& scene, int robot) {
  ObjectType type;
  EXPECT_TRUE(scene.FindType(kLedTypeName, &type));
  return scene.row<LedRow>(type, scene.FindObject("./led", scene.instance(robot).root), "led");
}

// The value gradient.c shows: value + 1 in base 4 over red, green, blue.
std::optional<int> GradientValue(const LedRow& led) {
  if (!led.on) return std::nullopt;
  const int code = static_cast<int>(std::lround(led.color.x * 3)) +
                   4 * static_cast<int>(std::lround(led.color.y * 3)) +
                   16 * static_cast<int>(std::lround(led.color.z * 3));
  if (code == 0) return std::nullopt;
  return code - 1;
}

// Hop counts from robot 0 over robots within `range` of each other (-1: unreached).
std::vector<int> HopCounts(const Scene& scene, int robots, double range) {
  std::vector<int> hops(robots, -1);
  std::vector<int> queue = {0};
  hops[0] = 0;
  for (size_t head = 0; head < queue.size(); ++head) {
    const Vec3 p = Position(scene, queue[head]);
    for (int j = 0; j < robots; ++j) {
      if (hops[j] >= 0) continue;
      const Vec3 q = Position(scene, j);
      if (std::hypot(p.x - q.x, p.y - q.y) <= range) {
        hops[j] = hops[queue[head]] + 1;
        queue.push_back(j);
      }
    }
  }
  return hops;
}

void Steps(World& world, int n) {
  for (int i = 0; i < n; ++i) world.Step();
}

TEST(KilobotDemosTest, GradientValuesEqualHopCounts) {
  for (int threads : {1, 2}) {
    LoadedWorld w = Load("kilobot/gradient.yaml", threads);
    World& world = *w.world;
    world.Start();
    Steps(world, 32 * 20);
    const Scene& scene = world.scene();
    const int n = world.robot_count();
    ASSERT_EQ(n, 100);
    const std::vector<int> hops = HopCounts(scene, n, 0.1);
    for (int i = 0; i < n; ++i) {
      // On the 6 cm lattice, neighbours and diagonals are one hop: the
      // Chebyshev distance from the corner robot 0.
      EXPECT_EQ(hops[i], std::max(i % 10, i / 10)) << "robot " << i;
      EXPECT_EQ(GradientValue(Led(scene, i)), hops[i]) << "robot " << i << ", " << threads;
    }
    world.Stop();
  }
}

TEST(KilobotDemosTest, GradientFormsOnAScatteredSwarm) {
  LoadedWorld w = Load("experiments/gradient_formation.yaml");
  World& world = *w.world;
  world.Start();
  const Scene& scene = world.scene();
  const int n = world.robot_count();
  Steps(world, 8);
  const std::vector<int> hops = HopCounts(scene, n, 0.1);
  int far = 0, right_early = 0;
  for (int i = 0; i < n; ++i) {
    far = std::max(far, hops[i]);
    if (GradientValue(Led(scene, i)) == hops[i]) ++right_early;
  }
  EXPECT_GE(far, 6);  // a gradient of several hops, not a clique
  EXPECT_LT(right_early, n / 2) << "after 0.25 s the far robots cannot know yet";
  Steps(world, 32 * 30 - 8);
  int right = 0, reached = 0;
  for (int i = 0; i < n; ++i) {
    if (hops[i] < 0) continue;
    ++reached;
    if (GradientValue(Led(scene, i)) == hops[i]) ++right;
  }
  EXPECT_GT(reached, n * 9 / 10);
  EXPECT_EQ(right, reached);
  world.Stop();
}

// Angle of `p` about `c`, unwrapped against `previous`.
double Unwrapped(double previous, const Vec3& p, const Vec3& c) {
  double a = std::atan2(p.y - c.y, p.x - c.x);
  while (a - previous > kPi) a -= 2 * kPi;
  while (a - previous < -kPi) a += 2 * kPi;
  return a;
}

TEST(KilobotDemosTest, ThePlanetKeepsItsDistanceWhileItGoesRound) {
  LoadedWorld w = Load("kilobot/orbit.yaml");
  World& world = *w.world;
  world.Start();
  const Scene& scene = world.scene();
  const Vec3 star = Position(scene, 0);
  double angle = Unwrapped(0, Position(scene, 1), star), start = angle;
  double nearest = 1, farthest = 0;
  for (int step = 0; step < 32 * 180; ++step) {
    world.Step();
    const Vec3 p = Position(scene, 1);
    angle = Unwrapped(angle, p, star);
    if (step >= 32 * 10) {  // past the first turn towards the star
      const double d = std::hypot(p.x - star.x, p.y - star.y);
      nearest = std::min(nearest, d);
      farthest = std::max(farthest, d);
    }
  }
  const Vec3 star_end = Position(scene, 0);
  EXPECT_LT(std::hypot(star_end.x - star.x, star_end.y - star.y), 1e-9) << "the star stays put";
  std::printf("orbit: distance %.4f .. %.4f m, swept %.2f turns\n", nearest, farthest,
              (start - angle) / (2 * kPi));
  EXPECT_GT(nearest, 0.040);
  EXPECT_LT(farthest, 0.085);
  EXPECT_GT(start - angle, 2 * kPi) << "clockwise, at least one full turn";
  world.Stop();
}

// How together the robots flash: over the next 96 steps (3 s, more than
// sync.c's period of 64 Kilobot ticks, 66 steps), the step at which each
// robot's LED lights first, as an angle on that period; the mean resultant
// length of those angles: 1 when all light at once, about 1/sqrt(n) when
// they light at random.
double FlashCoherence(World& world, bool all_flash) {
  const Scene& scene = world.scene();
  const int n = world.robot_count();
  const double period_steps = 64.0 / 31 * 32;  // ticks / (ticks per s) * (steps per s)
  std::vector<bool> was(n), seen(n, false);
  for (int i = 0; i < n; ++i) was[i] = Led(scene, i).lit();
  double c = 0, s = 0;
  for (int step = 0; step < 96; ++step) {
    world.Step();
    for (int i = 0; i < n; ++i) {
      const bool lit = Led(scene, i).lit();
      if (lit && !was[i] && !seen[i]) {
        seen[i] = true;
        c += std::cos(2 * kPi * step / period_steps);
        s += std::sin(2 * kPi * step / period_steps);
      }
      was[i] = lit;
    }
  }
  // (At the start a robot may skip one flash: a clock moved past it.)
  if (all_flash) {
    for (int i = 0; i < n; ++i) EXPECT_TRUE(seen[i]) << "robot " << i << " never flashed";
  }
  return std::hypot(c, s) / n;
}

TEST(KilobotDemosTest, BlinksSynchronise) {
  LoadedWorld w = Load("kilobot/sync.yaml");
  World& world = *w.world;
  world.Start();
  const double before = FlashCoherence(world, false);
  Steps(world, 32 * 80);
  const double after = FlashCoherence(world, true);
  std::printf("sync: flash coherence %.3f at the start, %.3f after 86 s\n", before, after);
  EXPECT_LT(before, 0.5);
  EXPECT_GT(after, 0.97);
  world.Stop();
}

double MeanNearest(const Scene& scene, int n, double* min_out) {
  double sum = 0, least = 1e9;
  for (int i = 0; i < n; ++i) {
    double best = 1e9;
    const Vec3 p = Position(scene, i);
    for (int j = 0; j < n; ++j)
      if (j != i) {
        const Vec3 q = Position(scene, j);
        best = std::min(best, std::hypot(p.x - q.x, p.y - q.y));
      }
    sum += best;
    least = std::min(least, best);
  }
  *min_out = least;
  return sum / n;
}

TEST(KilobotDemosTest, APackedSwarmDisperses) {
  LoadedWorld w = Load("kilobot/disperse.yaml");
  World& world = *w.world;
  world.Start();
  const Scene& scene = world.scene();
  const int n = world.robot_count();
  double min_before = 0, min_after = 0;
  const double before = MeanNearest(scene, n, &min_before);
  Steps(world, 32 * 300);
  const double after = MeanNearest(scene, n, &min_after);
  int stopped = 0;
  for (int i = 0; i < n; ++i)
    if (Led(scene, i).color.y > 0 && Led(scene, i).color.x == 0) ++stopped;
  std::printf("disperse: nearest %.3f (least %.3f) -> %.3f (least %.3f), %d of %d stopped\n",
              before, min_before, after, min_after, stopped, n);
  EXPECT_LT(before, 0.05);
  EXPECT_GT(after, 0.07);
  EXPECT_GT(stopped, n * 8 / 10);
  world.Stop();
}

TEST(KilobotDemosTest, TheEdgeFollowerGoesRoundTheGroup) {
  LoadedWorld w = Load("kilobot/edge_follow.yaml");
  World& world = *w.world;
  world.Start();
  const Scene& scene = world.scene();
  const int n = world.robot_count();
  Vec3 centre{0, 0, 0};
  for (int i = 1; i < n; ++i) centre = centre + Position(scene, i) * (1.0 / (n - 1));
  double angle = Unwrapped(0, Position(scene, 0), centre), start = angle;
  double nearest = 1, farthest = 0;
  for (int step = 0; step < 32 * 300; ++step) {
    world.Step();
    const Vec3 p = Position(scene, 0);
    angle = Unwrapped(angle, p, centre);
    if (step < 32 * 10) continue;
    double d = 1;
    for (int i = 1; i < n; ++i) {
      const Vec3 q = Position(scene, i);
      d = std::min(d, std::hypot(p.x - q.x, p.y - q.y));
    }
    nearest = std::min(nearest, d);
    farthest = std::max(farthest, d);
  }
  std::printf("edge: distance to the group %.4f .. %.4f m, swept %.2f turns\n", nearest, farthest,
              (start - angle) / (2 * kPi));
  EXPECT_GT(nearest, 0.035);
  EXPECT_LT(farthest, 0.090);
  EXPECT_GT(start - angle, 2 * kPi) << "clockwise, at least once round";
  world.Stop();
}

double FinalOpinionA(const std::vector<fs::path>& plugin_dirs) {
  LoadedWorld w = Load("experiments/best_of_n.yaml", 2, {}, plugin_dirs);
  World& world = *w.world;
  world.Start();
  Steps(world, 32 * 1800);
  const Scene& scene = world.scene();
  int a = 0;
  for (int i = 0; i < world.robot_count(); ++i) a += Led(scene, i).color.x > 0 ? 1 : 0;
  world.Stop();
  return static_cast<double>(a) / world.robot_count();
}

TEST(KilobotDemosTest, BestOfNAgreesOnTheBetterOption) {
  const double a = FinalOpinionA({});
  // The same program with the qualities swapped, built as a user would.
  const fs::path dir = testing::FreshTempDir("swarmsim_kilobot_demos", "swapped");
  fs::create_directories(dir);
  const testing::CommandResult built =
      testing::RunProgram("kilobot build " + WorldFile("kilobot/best_of_n.c") + " -o " +
                          (dir / "kilobot_best_of_n.so").string() +
                          " --name kilobot_best_of_n -- -DQUALITY_A=128 -DQUALITY_B=255");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const double swapped = FinalOpinionA({dir});
  std::printf("best-of-n: option A holds %.2f (A better), %.2f (B better)\n", a, swapped);
  EXPECT_GT(a, 0.9);
  EXPECT_LT(swapped, 0.1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
