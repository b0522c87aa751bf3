// `swarmsim bench` (swarm/bench/bench.cc): its default world found, the world
// checked before the table, one configuration measured in a process as one
// CSV row, and the table and CSV of every configuration.
#include "swarm/bench/bench.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

const std::string kDiffusion = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml";

std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream s(line);
  for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
  return fields;
}

std::string PrepareError(BenchOptions options) {
  try {
    PrepareBench(&options);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Runs `f` in folder `dir`, then comes back.
template <typename F>
void InFolder(const fs::path& dir, F f) {
  const fs::path before = fs::current_path();
  fs::current_path(dir);
  f();
  fs::current_path(before);
}

TEST(BenchTest, TheDefaultWorldIsTheRepositorysDiffusionWorld) {
  // The tests run from build/tests/, beside no worlds/: the current folder's.
  InFolder(SWARMSIM_SOURCE_DIR, [] { EXPECT_EQ(DefaultBenchWorld(), "worlds/diffusion.yaml"); });
  const fs::path elsewhere = testing::FreshTempDir("bench_test", "elsewhere");
  fs::create_directories(elsewhere);
  InFolder(elsewhere, [] {
    EXPECT_EQ(DefaultBenchWorld(), "");
    EXPECT_EQ(PrepareError({}),
              "bench: no --world given and the default world worlds/diffusion.yaml was found "
              "neither beside the program nor in the current folder; pass --world FILE");
  });
  fs::remove_all(elsewhere);
}

TEST(BenchTest, TheWorldIsCheckedAndGivesTheBareEngineRow) {
  BenchOptions options;
  options.world = kDiffusion;
  EXPECT_EQ(PrepareBench(&options), "box2d-only");
  options.world = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/wheeled3d.yaml";
  EXPECT_EQ(PrepareBench(&options), "ode-only");
  options.world = "/nonexistent/w.yaml";
  EXPECT_EQ(PrepareError(options), "bench: world file '/nonexistent/w.yaml' not found");
  // No `robots` parameter; and a world's own mistake, as loading it says.
  const fs::path dir = testing::FreshTempDir("bench_test", "worlds");
  fs::create_directories(dir);
  std::ofstream(dir / "fixed.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n";
  options.world = (dir / "fixed.yaml").string();
  EXPECT_EQ(PrepareError(options),
            "bench: world '" + options.world +
                "' has no parameter 'robots'; bench sets the robot count through it (declare "
                "parameters: {robots: N} and use count: $robots in its models entry)");
  std::ofstream(dir / "typo.yaml") << "simulation: {physics: kinematic, time_stpe: 0.1}\n"
                                      "parameters: {robots: 2}\n";
  options.world = (dir / "typo.yaml").string();
  const std::string typo = PrepareError(options);
  EXPECT_NE(typo.find("typo.yaml:1:"), std::string::npos) << typo;
  EXPECT_NE(typo.find("unknown key 'time_stpe'"), std::string::npos) << typo;
  // An arena sized by the count, too small for its pillar at one robot: the
  // world as written tells the engine (the counts asked for are measured).
  std::ofstream(dir / "disc.yaml")
      << "model: disc\nobjects: {name: body, type: shape, "
         "shape: cylinder, radius: 0.05, height: 0.05, dynamic: true}\n";
  std::ofstream(dir / "pillar.yaml")
      << "simulation: {physics: box2d, time_step: 0.1}\n"
         "parameters: {robots: 40}\n"
         "arena: {size: \"= sqrt(robots / 4)\"}\n"
         "obstacles: [{name: pillar, shape: cylinder, radius: 0.6, height: 0.2, "
         "position: [0, 0, 0.1]}]\n"
         "models: [{model: disc.yaml, count: $robots, distribute: {region: arena}}]\n";
  options.world = (dir / "pillar.yaml").string();
  EXPECT_EQ(PrepareError(options), "");
  EXPECT_EQ(PrepareBench(&options), "box2d-only");
  fs::remove_all(dir);
}

TEST(BenchTest, AChildMeasuresOneConfigurationAsOneCsvRow) {
  BenchOptions options;
  options.world = kDiffusion;
  options.steps = 3;
  options.warmup_steps = 1;
  for (const std::string config : {"diffusion", "box2d-only"}) {
    std::ostringstream out;
    ASSERT_EQ(RunBenchChild(options, config, 4, 2, out), 0);
    const std::string text = out.str();
    ASSERT_EQ(text.find('\n'), text.size() - 1) << "one row: " << text;
    const std::vector<std::string> f = Fields(text.substr(0, text.size() - 1));
    ASSERT_EQ(f.size(), 14u) << text;
    EXPECT_EQ(f[0], config);
    EXPECT_EQ(f[1], "4");
    EXPECT_EQ(f[2], config == "diffusion" ? "2" : "1") << "the bare engine runs on one thread";
    EXPECT_EQ(f[3], "3");
    const double wall = std::stod(f[4]), rate = std::stod(f[5]);
    ASSERT_GT(wall, 0) << text;
    EXPECT_NEAR(rate, 4 * 3 / wall, 1e-6 * rate) << "robot-ticks per second";
    EXPECT_GT(std::stod(f[9]), 0) << "physics time per tick: " << text;
    EXPECT_GT(std::stod(f[11]), 0) << "peak memory: " << text;
    EXPECT_GT(std::stod(f[13]), 0) << "start-up (load to first step): " << text;
  }
  std::ostringstream out;
  try {
    RunBenchChild(options, "ode-onyl", 4, 1, out);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "unknown bench configuration 'ode-onyl'");
  }
}

TEST(BenchTest, ARunIsOneProcessPerRowIntoTheTableAndTheCsv) {
  const fs::path dir = testing::FreshTempDir("bench_test", "run");
  fs::create_directories(dir);
  BenchOptions options;
  options.world = kDiffusion;
  options.robots = {2, 3};
  options.threads = {1};
  options.steps = 2;
  options.csv = (dir / "bench.csv").string();
  options.self_exe = SWARMSIM_BINARY;
  std::ostringstream out, err;
  ASSERT_EQ(RunBench(options, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("world " + kDiffusion + ", 2 measured steps after 20 warm-up steps"),
            std::string::npos)
      << out.str();
  std::ifstream csv(*options.csv);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(csv, line);) rows.push_back(Fields(line));
  ASSERT_EQ(rows.size(), 5u) << "the header, then diffusion and box2d-only for 2 and 3 robots";
  EXPECT_EQ(rows[0].front(), "config");
  EXPECT_EQ(rows[0].size(), 14u);
  EXPECT_EQ(rows[0].back(), "startup_s");
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"diffusion", "2"}, {"box2d-only", "2"}, {"diffusion", "3"}, {"box2d-only", "3"}};
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(rows[i + 1][0], expected[i].first) << i;
    EXPECT_EQ(rows[i + 1][1], expected[i].second) << i;
  }
  // A program that cannot run: each row fails, said on `err`, and the run too.
  options.self_exe = "/nonexistent/swarmsim";
  options.robots = {2};
  options.csv.reset();
  std::ostringstream out2, err2;
  EXPECT_EQ(RunBench(options, out2, err2), 1);
  EXPECT_NE(err2.str().find("bench: diffusion with 2 robots on 1 thread failed"), std::string::npos)
      << err2.str();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
