#include "swarm/run/summary_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "framework/output_file.h"
#include "framework/registry.h"
#include "framework/regular_file.h"
#include "framework/state_hash.h"
#include "framework/utf8.h"
#include "framework/world.h"
#include "swarm/run/huge_pages.h"
#include "swarm/run/output_folder.h"
#include "swarm/run/version.h"

namespace swarmsim {

namespace {

// A double that JSON should show as an integer: whole and exact (|v| <= 2^53).
bool IsWholeNumber(double v) { return std::abs(v) <= 9007199254740992.0 && v == std::trunc(v); }

// Writes `bytes` over the file at `path` in the blocks it already holds:
// on a full disk there is no room for a copy beside it, but the summary
// written at the start (status "running") has room for the last one. Only
// when `bytes` fit in what the file holds (a cut JSON is worse than the
// old one); false otherwise.
bool OverwriteInPlace(const std::filesystem::path& path, std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
            static_cast<uint64_t>(st.st_blocks) * 512 >= bytes.size();
  for (size_t done = 0; ok && done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += static_cast<size_t>(n);
  }
  ok = ok && ::ftruncate(fd, static_cast<off_t>(bytes.size())) == 0;
  return ::close(fd) == 0 && ok;
}

}  // namespace

// The simulated time at the end of the last step that finished: the
// world's, unless a step failed after its physics had moved the clock on
// (out of memory in its recording: the summary said 4 steps and 0.5 s).
double FinishedTime(const World& world, const RunResult& result) {
  if (world.step_count() == result.first_step + result.steps) return world.time();
  return static_cast<double>(result.first_step + result.steps) * world.settings().time_step;
}

// The simulated seconds this process ran: a run resumed from a state
// (--load-state) counts its own steps, not the saved run's (its real-time
// factor divided the whole history by its own wall time).
double SimulatedThisRun(const World& world, const RunResult& result) {
  return result.first_step > 0
             ? FinishedTime(world, result) -
                   static_cast<double>(result.first_step) * world.settings().time_step
             : FinishedTime(world, result);
}

// summary.json, written whole or not at all (WriteFileAtomically); returns
// "" or why it could not be written. `complete`: the world is between steps;
// else a step is stuck (Watchdog) and what a running step may change is
// left out: the state hash and the disabled scripts. `status` replaces the
// result's own ("running" while the run goes).
std::string WriteSummary(const World& world, const RunOptions& options, const RunResult& result,
                         double lua_kib, bool complete, const char* status) {
  const int robots = world.live_robot_count();  // removed robots are not counted
  const double sim_time = FinishedTime(world, result);
  const double robot_ticks = static_cast<double>(robots) * static_cast<double>(result.steps);
  nlohmann::json j;
  j["swarmsim_version"] = Version();
  j["world"] = options.world_file;
  j["command"] = options.command_line;
  j["status"] = status != nullptr    ? status
                : result.ok          ? "ok"
                : result.signal != 0 ? "interrupted"
                                     : "error";
  if (!result.ok && status == nullptr) j["error"] = result.error;
  j["seed"] = world.settings().seed;
  j["threads"] = world.threads();
  j["physics"] = world.settings().physics;
  j["robots"] = robots;
  j["steps"] = result.steps;
  if (!options.resumed_from.empty())
    j["resumed_from"] = {{"file", options.resumed_from}, {"step", result.first_step}};
  if (result.saved_step >= 0)
    j["state_saved"] = {{"file", options.save_state->string()}, {"step", result.saved_step}};
  j["time_step"] = world.settings().time_step;
  // null where the backend takes no substeps (kinematic, planar), as the
  // table's physics line leaves them out.
  if (world.registry().dynamics_capabilities(world.settings().physics).substeps)
    j["physics_substeps"] = world.settings().physics_substeps;
  else
    j["physics_substeps"] = nullptr;
  j["simulated_time"] = sim_time;
  j["wall_time"] = result.wall_seconds;
  j["start_time"] = result.start_seconds;  // of wall_time: starting the world
  if (options.load_seconds >= 0) j["load_time"] = options.load_seconds;  // before wall_time
  j["real_time_factor"] =
      result.wall_seconds > 0 ? SimulatedThisRun(world, result) / result.wall_seconds : 0;
  j["robot_ticks_per_s"] = result.wall_seconds > 0 ? robot_ticks / result.wall_seconds : 0;
  j["peak_rss_mb"] = result.peak_rss_mb;
  j["huge_pages"] = HugePagesRequested();
  j["lua_memory_kib"] = lua_kib;
  // Robots a Lua state (simulation.robots_per_lua_state; 1 under --trust-scripts).
  j["robots_per_lua_state"] =
      world.settings().trust_scripts ? 1 : world.settings().robots_per_lua_state;
  j["state_hash"] = complete ? nlohmann::json(StateHasher::ToHex(result.state_hash)) : nullptr;
  if (complete) j["disabled_scripts"] = world.disabled_scripts();
  nlohmann::json phases;
  for (size_t p = 0; p < static_cast<size_t>(Phase::kCount); ++p)
    phases[ToString(static_cast<Phase>(p))] = world.phase_times()[p];
  j["phase_seconds"] = phases;
  nlohmann::json params;
  for (const auto& [name, value] : world.parameters()) {
    if (const double* d = std::get_if<double>(&value))
      params[name] = IsWholeNumber(*d) ? nlohmann::json(static_cast<int64_t>(*d))
                                       : nlohmann::json(*d);  // 50, not 50.0
    else if (const bool* b = std::get_if<bool>(&value))
      params[name] = *b;
    else
      params[name] = std::get<std::string>(value);
  }
  j["parameters"] = params;
  nlohmann::json overrides = nlohmann::json::object();
  for (const auto& [name, value] : options.overrides) overrides[name] = value;
  j["overrides"] = overrides;
  // The modules' files (graphs, snapshots, video), once the run has started.
  nlohmann::json outputs = nlohmann::json::array();
  if (world.started())
    for (const OutputFile& file : world.ListOutputs())
      outputs.push_back(
          {{"kind", file.kind}, {"path", file.path}, {"description", file.description}});
  j["outputs"] = outputs;
  // Invalid UTF-8 (from a world file, a script, a --set) is replaced, not fatal.
  const std::filesystem::path path = *options.out_dir / "summary.json";
  const std::string text = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  const std::string reason = TryWriteFileAtomically(path, text);
  if (reason.empty()) return "";
  // No room beside it (a full disk): over the summary already there, whole,
  // or its first lines (how the run ended) if the whole does not fit.
  if (OverwriteInPlace(path, text)) return "";
  nlohmann::json last;
  for (const char* key : {"swarmsim_version", "world", "command", "status", "error", "steps"})
    if (j.contains(key)) last[key] = j[key];
  if (OverwriteInPlace(path,
                       last.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n"))
    return "";
  return reason;
}

std::string WriteErrorSummary(const RunOptions& options, const std::string& error,
                              const std::string& status) {
  if (!options.out_dir) return "no output folder";
  std::error_code ec;
  std::filesystem::create_directories(*options.out_dir, ec);
  if (ec) return ec.message();
  // This summary replaces an earlier run's: its files go too (they stayed,
  // unlisted, beside the next run's), metrics.csv with them.
  if (const std::string note = RemoveEarlierOutputs(*options.out_dir, /*metrics_too=*/true);
      !note.empty())
    std::cerr << "note: " << ValidUtf8(note) << "\n";
  nlohmann::json j;
  j["swarmsim_version"] = Version();
  j["world"] = options.world_file;
  j["command"] = options.command_line;
  j["status"] = status;
  j["error"] = error;
  // Invalid UTF-8 (from a world file, a script, a --set) is replaced, not fatal.
  return TryWriteFileAtomically(
      *options.out_dir / "summary.json",
      j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

}  // namespace swarmsim
