// `swarmsim bench --scaling`: robot-ticks/s over robot counts x threads
// (1 .. cores) and sweep throughput (runs per minute at --jobs 1 .. cores);
// a table, a CSV and a PNG plot of speed-up with the ideal line.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "swarm/bench/bench.h"

namespace swarmsim {

struct ScalingOptions {
  BenchOptions bench;          // world, robots, threads, steps; csv unused
  bool threads_given = false;  // else threads 1 .. cores
  std::vector<int> jobs;       // empty: 1 .. cores
  int sweep_runs = 16;         // runs per sweep measurement
  int sweep_robots = 100;
  int sweep_steps = 200;
  std::string csv = "scaling.csv";
  std::string plot = "scaling.png";
};

int RunScalingBench(ScalingOptions options, std::ostream& out, std::ostream& err);

// Runs gnuplot on `script` (the plots of the bench commands); false, with a
// line on `err`, when gnuplot is missing or fails.
bool RunGnuplot(const std::string& script, std::ostream& err);

// The --csv and --plot files of --scaling and --scaling-robots, checked
// before anything is measured (CheckBenchOutput; two names of one file are
// refused). Throws swarmsim::Error.
void CheckScalingOutputs(const std::string& csv, const std::string& plot);

}  // namespace swarmsim
