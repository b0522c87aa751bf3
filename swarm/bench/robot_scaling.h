// `swarmsim bench --scaling-robots`: what a robot-tick costs from 1,000 to
// 1,000,000 robots, per phase, for the Lua, C++, planar + Lua and planar +
// C++ diffusion worlds; one table, a CSV and a log-log PNG, with start-up time and peak
// memory per row (issue 32).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace swarmsim {

// One world measured at every robot count: "lua" (worlds/diffusion.yaml),
// "cpp" (worlds/diffusion_native.yaml), "planar-lua"
// (worlds/diffusion_planar.yaml), "planar-cpp"
// (bench/worlds/diffusion_planar_native.yaml), or a --world's file stem.
struct ScalingConfig {
  std::string name;
  std::string world;
};

struct RobotScalingOptions {
  std::vector<ScalingConfig> configs;  // empty: the four diffusion worlds (DefaultScalingConfigs)
  std::vector<int> robots{1000, 10000, 100000};
  std::vector<int> threads;   // empty: every core
  int64_t steps = 0;          // measured steps per row; 0: AutoScalingSteps(robots)
  int64_t warmup_steps = -1;  // -1: AutoWarmupSteps(steps)
  // Rounds: every row measured once per round, rounds one after the other
  // (a machine whose speed drifts then weighs on every row alike); each row
  // reports its round of median total.
  int repeat = 1;
  std::string csv = "scaling_robots.csv";
  std::string plot = "scaling_robots.png";
  std::string self_exe;  // this program, re-run once per row
};

// About two million measured robot-ticks per row: 1,000 steps at 1,000
// robots, 200 at 10,000, 20 at 100,000, 3 (the least) at 1,000,000.
int64_t AutoScalingSteps(int robots);
// A tenth of the measured steps, from 2 to 20: wheel commands settle.
int64_t AutoWarmupSteps(int64_t steps);

// The four diffusion worlds of the source tree the program was built in
// (else of the current folder). Throws swarmsim::Error naming a missing one.
std::vector<ScalingConfig> DefaultScalingConfigs();
// The default configurations named in `names` ("lua,planar-cpp"); throws
// swarmsim::Error for an unknown name, listing the known ones.
std::vector<ScalingConfig> SelectScalingConfigs(const std::vector<std::string>& names);

// Measures every configuration x robot count x thread count, one child
// process per row, prints the table to `out` as rows come, writes the CSV
// and the plot (gnuplot). Every world is checked (it loads, has a `robots`
// parameter) before any output; a world it refuses throws swarmsim::Error.
// Returns 0, or 1 when a row or the plot failed (said on `err`).
int RunRobotScalingBench(RobotScalingOptions options, std::ostream& out, std::ostream& err);

}  // namespace swarmsim
