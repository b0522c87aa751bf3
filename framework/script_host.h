// The Lua scripting host: World's ScriptHost (framework/phase_handlers.h),
// made by MakeScriptHost.
//
// One lua_State per model instance (robot), or per n robots
// (simulation.robots_per_lua_state); each script attached to an object of
// a robot is a separate environment in it. Scripts outside any
// model share one scene state that runs on the calling thread. Lua types
// stay inside the host's .cc files (lua_api.h is internal to them).
//
// The sim.* API is in lua_api_*.cc, one file per area; each function's
// comment is its reference. A Lua error becomes a swarmsim::Error reading
// "footbot#12: scripts/x.lua:23: <message> [in sysCall_actuation of
// /footbot#12/body]".
#pragma once

#include <string>
#include <vector>

#include "framework/phase_handlers.h"

namespace swarmsim {

// The script calls running right now on any thread, innermost first per
// thread: "footbot#3: probe.lua, in sysCall_actuation of /footbot#3/body".
// For a watchdog that finds a run stuck in one call (Lua's hooks cannot stop
// a script inside one C function, such as a pattern match that backtracks
// for hours); safe to call from any thread while scripts run.
std::vector<std::string> ScriptCallsInProgress();

}  // namespace swarmsim
