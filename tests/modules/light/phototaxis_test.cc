// worlds/phototaxis.yaml: foot-bots with 8 light sensors drive to the lamp.
// Their mean distance to it (in the plane) falls below a third of where it
// started, while with the lamp at intensity 0 (nothing to read: they drive
// straight and turn at obstacles) it stays above two thirds; the run is
// the same at 1 and 2 threads, with the state hash of the golden table.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

struct PhotoRun {
  double start = 0, end = 0;  // mean distance to the lamp (m) before and after
  uint64_t hash = 0;          // after 200 steps (the golden table's)
};

double MeanDistance(const Scene& scene) {
  const Vec3 lamp = scene.world_pose(scene.FindObject("/lamp")).p;
  double sum = 0;
  int n = 0;
  for (const ModelInstance& robot : scene.instances()) {
    const Vec3 p = scene.world_pose(robot.root).p;
    sum += std::hypot(p.x - lamp.x, p.y - lamp.y);
    ++n;
  }
  EXPECT_EQ(n, 20);
  return sum / n;
}

PhotoRun RunPhototaxis(int threads, const std::string& intensity) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions options;
  options.threads = threads;
  options.overrides.push_back({"intensity", intensity});
  LoadedWorld w =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/phototaxis.yaml", options, registry);
  w.world->set_log_sink([](std::string_view) {});
  PhotoRun run;
  run.start = MeanDistance(w.world->scene());
  w.world->Start();
  for (int step = 0; step < 600; ++step) {
    w.world->Step();
    if (step == 199) run.hash = w.world->StateHash();
  }
  run.end = MeanDistance(w.world->scene());
  return run;
}

// The golden table's hash of the world (seed 1, 200 steps, `threads`).
std::string GoldenHash(int threads) {
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/golden_hashes.tsv");
  std::string line;
  const std::string key = "worlds/phototaxis.yaml\t1\t200\t" + std::to_string(threads) + "\t";
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return line.substr(key.size());
  return "(no row)";
}

TEST(PhototaxisTest, RobotsGatherUnderTheLampOnlyWhenItShines) {
  const PhotoRun lit = RunPhototaxis(1, "1");
  const PhotoRun dark = RunPhototaxis(1, "0");
  EXPECT_GT(lit.start, 1.5);  // spread over the 5 m arena
  EXPECT_LT(lit.end, lit.start / 3);
  EXPECT_EQ(dark.start, lit.start);
  EXPECT_GT(dark.end, 2 * dark.start / 3);
}

TEST(PhototaxisTest, OneAndTwoThreadsGiveTheSameRunAndTheGoldenHash) {
  const PhotoRun one = RunPhototaxis(1, "1");
  const PhotoRun two = RunPhototaxis(2, "1");
  EXPECT_EQ(one.hash, two.hash);
  EXPECT_EQ(one.end, two.end);
  EXPECT_EQ(StateHasher::ToHex(one.hash), GoldenHash(1));
  EXPECT_EQ(StateHasher::ToHex(two.hash), GoldenHash(2));
}

}  // namespace
}  // namespace swarmsim
