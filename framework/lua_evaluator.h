// A limited Lua state for short evaluations outside any script, under the
// script host's own limits: its allocator (LimitedAlloc, against a memory
// limit) and its count hook (an instruction budget that pcall cannot
// catch). The loader's "= expression" values run in one
// (swarm/loader/values.cc); the host's script states are the same kind of
// state (script_state.h, script_hooks.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

struct lua_State;

namespace swarmsim {

namespace lua_host {
struct ScriptState;
}

class LimitedLua {
 public:
  // A state with no library open. `subject` names what runs in the errors
  // ("the expression ran more than 1000000 Lua instructions ..."). Throws
  // swarmsim::Error if the state cannot be made.
  LimitedLua(const char* subject, size_t memory_limit, int64_t instruction_budget);
  ~LimitedLua();
  LimitedLua(const LimitedLua&) = delete;
  LimitedLua& operator=(const LimitedLua&) = delete;

  lua_State* L() const;

  // lua_pcall(L, nargs, nresults) under a fresh instruction budget. On
  // failure, returns false with the error's text in *error (a spent budget
  // or the memory limit named as such, whatever error value the call left)
  // and the stack emptied.
  bool Call(int nargs, int nresults, std::string* error);

 private:
  std::unique_ptr<lua_host::ScriptState> state_;
};

}  // namespace swarmsim
