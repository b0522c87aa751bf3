// LimitedLua (lua_evaluator.h): a ScriptState without scripts, so the
// host's allocator and hooks apply unchanged.
#include "framework/lua_evaluator.h"

#include <string>

#include "framework/error.h"
#include "framework/script_hooks.h"
#include "framework/script_state.h"

namespace swarmsim {

namespace {
int ThrowOnPanic(lua_State* L) {
  const char* message = lua_tostring(L, -1);
  throw Error(std::string("Lua: ") + (message != nullptr ? message : "unprotected error"));
}
}  // namespace

LimitedLua::LimitedLua(const char* subject, size_t memory_limit, int64_t instruction_budget)
    : state_(std::make_unique<lua_host::ScriptState>()) {
  lua_host::ScriptState& state = *state_;
  state.heap = std::make_shared<lua_host::LuaHeap>();
  LuaContext& c = state.context;
  c.name = subject;
  c.host_state = &state;
  c.instruction_budget = instruction_budget;
  c.budget_subject = subject;
  c.budget_setting = "";
  state.heap->memory.own.Attach(nullptr, memory_limit);
  c.memory = &state.heap->memory.own;
  state.heap->memory.holder = subject;
  state.heap->memory.plural = false;
  state.heap->memory.setting = "the limit of one evaluation";
  state.L = lua_newstate(lua_host::LimitedAlloc, state.heap.get());
  if (state.L == nullptr) throw Error(std::string("not enough memory for a Lua state"));
  state.heap->L = state.L;
  state.heap->current = &state;
  lua_atpanic(state.L, ThrowOnPanic);
  SetContext(state.L, &c);
}

LimitedLua::~LimitedLua() = default;  // ~ScriptState closes the state

lua_State* LimitedLua::L() const { return state_->L; }

bool LimitedLua::Call(int nargs, int nresults, std::string* error) {
  lua_host::ScriptState& state = *state_;
  lua_State* L = state.L;
  LuaContext& c = state.context;
  c.budget_exhausted = false;
  c.budget_error.clear();
  state.heap->memory.refusal_bytes = 0;
  lua_host::SetBudget(L, c);
  const int status = lua_pcall(L, nargs, nresults, 0);
  lua_sethook(L, nullptr, 0, 0);
  if (status == LUA_OK && !c.budget_exhausted) return true;
  *error = c.budget_exhausted ? c.budget_error : lua_host::ErrorText(L, status);
  lua_settop(L, 0);
  lua_gc(L, LUA_GCCOLLECT);
  return false;
}

}  // namespace swarmsim
