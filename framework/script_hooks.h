// Internal to the Lua host (script_*.cc, lua_api_control.cc): the count
// hooks that bound what a script may run and hold, and the resuming of a
// threaded script under its time slice.
//
// Every non-threaded callback runs under an instruction budget (a count
// hook that raises an error); explicit scripts run on their caller's. Once a
// callback used up its budget every further instruction raises again, so
// pcall cannot catch it, and the host reports the budget error whatever
// error value the callback returns. A threaded script's time slice is a
// count hook that yields (kInstructionsPerMs, script_state.h). Every state
// allocates through LimitedAlloc, against simulation.script_memory_limit
// (LuaMemory, script_state.h). FailCallback (lua_api.h) is defined here.
#pragma once

#include <cstddef>

#include "framework/lua_api.h"

namespace swarmsim::lua_host {

// A fresh budget for the next callback on L. Without a budget (0), a spent
// one's hook (left by the memory limit) goes, or it would fail every later
// callback of the state.
void SetBudget(lua_State* L, const LuaContext& c);

// Count hook of threads: the time slice is used up; yield if Lua can and L
// is the script's thread itself. A coroutine of the script's own inherits
// the hook (lua_newthread copies it) but is never yielded: that would hand
// control back to its resumer, not to the simulation. There, and inside a
// call that cannot yield (a C function calling Lua, e.g. a table.sort
// comparator), the instruction budget applies instead.
void SliceHook(lua_State* L, lua_Debug* ar);

struct Script;
struct ScriptState;
// Resumes `script`'s thread (sysCall_thread) under a fresh time slice until
// it yields, returns or fails; a failure or a spent budget ends the thread
// and throws the script's error (ThrowScriptError).
void ResumeThread(ScriptState* state, Script& script);

// lua_Alloc of every state (`ud`: its LuaHeap): realloc/free, counting
// against the state's memory limit.
void* LimitedAlloc(void* ud, void* ptr, size_t osize, size_t nsize);

}  // namespace swarmsim::lua_host
