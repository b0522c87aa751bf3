// Internal to the Lua host (script_*.cc): the sysCall_* names a script
// defines, checked once at load, with hints for those swarmsim never calls
// (typos, CoppeliaSim callbacks).
#pragma once

#include <string>
#include <vector>

#include "framework/script_state.h"

namespace swarmsim::lua_host {

// Once per script at load, after sysCall_init (which may define callbacks):
// a callback the script gets called must be a function (else a script error
// naming the file and the callback); any other global named sysCall_*
// (case aside: a typo, a CoppeliaSim callback) gets a warning in
// state.warnings, which LuaScriptHost::Start logs once per file. Warnings are
// in line order, then name order (the table's order is not deterministic);
// names that are not functions of the file's own come last.
void CheckSysCallNames(ScriptState& state, const Script& script);

// "; main.lua:3 defines sysCall_stpe: did you mean sysCall_step?" when the
// main script defines a name near sysCall_step (not one of swarmsim's or
// CoppeliaSim's own callbacks), else "".
std::string MisspeltStepHint(const std::vector<UncalledSysCall>& uncalled);

}  // namespace swarmsim::lua_host
