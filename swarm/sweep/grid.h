// The run grid of a sweep: parameter specs (lists, linear and log ranges),
// seeds, and their cartesian product.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace swarmsim {

// One `--param NAME=SPEC`. SPEC is a list `100,200,400`, a linear range
// `A:B:N` (N evenly spaced values from A to B inclusive) or a log range
// `log:A:B:N` (N values from A to B, evenly spaced in log10).
struct ParamSpec {
  std::string name;
  std::string spec;                 // as given
  std::string kind;                 // "list", "linear" or "log"
  std::vector<std::string> values;  // as passed to `run --set name=value`
};

// Throws swarmsim::Error with the offending text for a malformed spec.
ParamSpec ParseParamSpec(const std::string& name_equals_spec);

// `--seeds K` (seeds 1..K), `A-B` (A..B inclusive) or a list `3,7,11`.
std::vector<uint64_t> ParseSeeds(const std::string& spec);

// One run of the grid. Runs are numbered from 1, point-major: id = point * seeds + s + 1.
struct GridRun {
  int64_t id = 0;
  int64_t point = 0;  // index of the parameter combination
  uint64_t seed = 0;
  std::vector<std::pair<std::string, std::string>> params;  // in --param order
};

// The cartesian product of the parameter values (the last --param varies
// fastest) times the seeds.
std::vector<GridRun> ExpandGrid(const std::vector<ParamSpec>& params,
                                const std::vector<uint64_t>& seeds);

// A number printed the way it is passed on the command line (%.12g).
std::string FormatNumber(double value);

}  // namespace swarmsim
