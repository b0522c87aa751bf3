// summary.json: what a run writes of itself at its start ("running"), at
// its end and when a step is stuck (the Watchdog), whole or not at all;
// and the simulated time it reports. Used by runner.cc.
#pragma once

#include <string>

#include "swarm/run/runner.h"

namespace swarmsim {

class World;

// The simulated time at the end of the last step that finished: the
// world's, unless a step failed after its physics had moved the clock on
// (out of memory in its recording: the summary said 4 steps and 0.5 s).
double FinishedTime(const World& world, const RunResult& result);

// The simulated seconds this process ran: a run resumed from a state
// (--load-state) counts its own steps, not the saved run's (its real-time
// factor divided the whole history by its own wall time).
double SimulatedThisRun(const World& world, const RunResult& result);

// summary.json, written whole or not at all (WriteFileAtomically); on a
// full disk over the summary already there. Returns "" or why it could not
// be written. `complete`: the world is between steps; else a step is stuck
// (Watchdog) and what a running step may change is left out: the state
// hash and the disabled scripts. `status` replaces the result's own
// ("running" while the run goes).
std::string WriteSummary(const World& world, const RunOptions& options, const RunResult& result,
                         double lua_kib, bool complete, const char* status = nullptr);

}  // namespace swarmsim
