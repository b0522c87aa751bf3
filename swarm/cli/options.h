// What the commands share: option checks that say plainly what they expect,
// exit codes, and the few helpers more than one command needs.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace swarmsim::cli {

constexpr int kExitRunError = 1;  // the run failed (script error, physics, outputs)
constexpr int kExitBadInput = 2;  // bad command line or world file

constexpr int64_t kInt64Max = std::numeric_limits<int64_t>::max();
constexpr int64_t kIntMax = std::numeric_limits<int>::max();

// A number > 0, or >= 0 with `allow_zero` (CLI11's own range checks print the
// whole double range; these say it plainly).
CLI::Validator NumberCheck(bool allow_zero);
inline CLI::Validator NonNegativeCheck() { return NumberCheck(true); }

// A whole number from `min` to `max`, written in decimal, for transform():
// the text is rewritten in plain decimal, as CLI11 alone would read 010 as
// octal and 1e2 not at all. `what` names what it counts ("steps") in the
// messages; empty: the range is the message ("expected a whole number from 1
// to 1024").
CLI::Validator WholeNumberCheck(int64_t min, int64_t max, const std::string& what = "");
// run and bench --threads.
inline CLI::Validator ThreadCountCheck() { return WholeNumberCheck(1, 1024); }

// --seed: the world file's `seed` range, 0 .. 2^64-1, in decimal. CLI11 alone
// would read -1 as 2^64-1 and clamp what is past 2^64-1.
CLI::Validator SeedCheck();

// A file or folder name that must not be empty (`what`: "a folder").
CLI::Validator NonEmpty(const std::string& what);

// A memory size: 500M, 2G, 1.5GiB (K/M/G/T: powers of 1024), or bytes.
CLI::Validator MemorySizeCheck();

// Where a world's `plugins: [name]` are looked for: plugins/ beside the
// program (the build tree), and lib/swarmsim/plugins of an installed one.
std::vector<std::filesystem::path> PluginDirectories();

// --set NAME=VALUE options as pairs. Throws swarmsim::Error.
std::vector<std::pair<std::string, std::string>> ParseSets(const std::vector<std::string>& sets);

// The command line as typed (argv joined by spaces), for summaries and sweep records.
std::string CommandLine(int argc, char** argv);

}  // namespace swarmsim::cli
