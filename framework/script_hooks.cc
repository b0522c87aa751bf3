// The Lua host's count hooks: the instruction budget of callbacks, the time
// slice of threads, and the memory limit of states (script_hooks.h).
#include "framework/script_hooks.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include "framework/script_calls.h"
#include "framework/script_state.h"
#include "framework/small_blocks.h"
#include "framework/world.h"

namespace swarmsim {
namespace lua_host {
namespace {

// Steps in a row a thread's slice runs out before it is said to be stuck.
constexpr uint16_t kStuckThreadSteps = 100;

std::string MemoryLimitText(const LuaMemory& memory) {
  return std::string(memory.holder) + (memory.plural ? " hold" : " holds") + " more than " +
         MemoryLimitTail(memory);
}

// "file:line: " of the Lua function a hook interrupted, or "".
std::string HookWhere(lua_State* L, lua_Debug* ar) {
  if (lua_getinfo(L, "Sl", ar) == 0 || ar->currentline <= 0) return "";
  return std::string(ar->short_src) + ":" + std::to_string(ar->currentline) + ": ";
}

// Count hook once the running callback has used up its budget: every further
// instruction raises again, so pcall and xpcall cannot swallow the error.
// It is raised as Lua's memory error (lua_error recognizes Lua's own "not
// enough memory" string): an error raised from a hook would otherwise call
// xpcall's message handler with hooks off, free to loop forever. The Lua
// code sees "not enough memory"; the host reports budget_error.
void ExhaustedHook(lua_State* L, lua_Debug*) {
  lua_pushliteral(L, "not enough memory");
  lua_error(L);
}

// The running callback used up its budget: records `message` (the first
// one), arms ExhaustedHook on L and on the callback's root state (so that
// neither a new coroutine, which copies its creator's hook, nor the caller
// gets a fresh count) and raises. Call() and ResumeThread() report
// budget_error whatever error value reaches them.
template <typename MakeMessage>
void ExhaustBudget(lua_State* L, MakeMessage make_message) {
  LuaContext& c = Context(L);
  if (!c.budget_exhausted) {
    c.budget_exhausted = true;
    c.budget_error = make_message();  // a member: nothing is left to destroy at the longjmp
  }
  lua_sethook(L, ExhaustedHook, LUA_MASKCOUNT, 1);
  lua_sethook(RootOf(c), ExhaustedHook, LUA_MASKCOUNT, 1);
  ExhaustedHook(L, nullptr);
}

// Count hook of non-threaded callbacks: the budget is used up.
void BudgetHook(lua_State* L, lua_Debug* ar) {
  ExhaustBudget(L, [&] {
    const LuaContext& c = Context(L);
    std::string message = HookWhere(L, ar) + c.budget_subject + " ran more than " +
                          std::to_string(c.instruction_budget) +
                          " Lua instructions without returning (an endless loop?)";
    if (*c.budget_setting != '\0')
      message += std::string("; if the work is real, raise ") + c.budget_setting;
    return message;
  });
}

// Count hook armed when a state's memory passed the limit (LuaMemory).
void MemoryHook(lua_State* L, lua_Debug* ar) {
  auto* state = static_cast<ScriptState*>(Context(L).host_state);
  LuaMemory& m = state->heap->memory;
  if (std::exchange(m.refused_bytes, 0) > 0) {
    // Where it was asked for (a coroutine's line, when the refusal ended
    // one that the script resumed), else where the hook fired.
    ExhaustBudget(L, [&] {
      return (m.refusal_where[0] != '\0' ? "" : HookWhere(L, ar)) + RefusalText(*state);
    });
  }
  lua_gc(L, LUA_GCCOLLECT);
  // Still too much: fails the callback as a spent budget does, so pcall and
  // xpcall's handler cannot catch it and go on allocating.
  const ScriptMemory& account = *m.account;
  if (account.limit() > 0 && account.used() > account.limit())
    ExhaustBudget(L, [&] { return HookWhere(L, ar) + MemoryLimitText(m); });
  // Garbage only: the threads get their usual hooks back (the exhausted
  // budget's, if it ran out).
  SetBudget(state->L, state->context);
  for (const Script& script : state->scripts)
    if (script.thread != nullptr)
      lua_sethook(script.thread, SliceHook, LUA_MASKCOUNT, script.slice_instructions);
  if (state->context.budget_exhausted) {
    lua_sethook(L, ExhaustedHook, LUA_MASKCOUNT, 1);
    lua_sethook(RootOf(state->context), ExhaustedHook, LUA_MASKCOUNT, 1);
  }
}

// May the allocator read the running thread's stack (lua_getinfo) while
// it is asked to grow the block `ptr`? Lua 5.4.4 (Debian 12's) reallocates
// a stack into a fresh block, the old one intact meanwhile; from 5.4.5 it
// reallocates the stack in place, its frames' pointers turned into offsets
// for the time of the call, which lua_getinfo would read as pointers. There,
// only fresh blocks (strings, buffers, new tables) are located.
bool CanReadStackInAllocator([[maybe_unused]] const void* ptr) {
#if LUA_VERSION_RELEASE_NUM <= 50404
  return true;
#else
  return ptr == nullptr;
#endif
}

}  // namespace

void SetBudget(lua_State* L, const LuaContext& c) {
  const int64_t budget = c.instruction_budget;
  if (budget > 0)
    lua_sethook(L, BudgetHook, LUA_MASKCOUNT, static_cast<int>(std::min<int64_t>(budget, INT_MAX)));
  else if (lua_gethook(L) == ExhaustedHook)
    lua_sethook(L, nullptr, 0, 0);
}

void SliceHook(lua_State* L, lua_Debug* ar) {
  LuaContext& c = Context(L);
  if (c.thread == nullptr) {
    // A coroutine made by the thread, resumed from a non-threaded callback:
    // that callback's budget regime applies from now on.
    SetBudget(L, c);
    return;
  }
  if (L == c.thread && lua_isyieldable(L)) {
    c.slice_yielded = true;
    lua_yield(L, 0);
    return;
  }
  const int64_t budget = c.instruction_budget;
  const int count = lua_gethookcount(L);
  if (budget > 0 && ++c.slice_fires * count > budget) {
    ExhaustBudget(L, [&] {
      return HookWhere(L, ar) + "the thread ran more than " + std::to_string(budget) +
             " Lua instructions in a coroutine of its own or a call that cannot yield";
    });
  }
}

void* LimitedAlloc(void* ud, void* ptr, size_t osize, size_t nsize) {
  auto* heap = static_cast<LuaHeap*>(ud);
  LuaMemory& m = heap->memory;
  ScriptMemory& account = *m.account;
  const size_t old = ptr != nullptr ? osize : 0;
  if (nsize == 0) {
    small_blocks::Free(ptr, old);
    m.used -= old;
    account.ShrinkHeap(old);
    return nullptr;
  }
  if (nsize <= old) {  // Lua assumes that shrinking never fails
    void* p = small_blocks::Resize(ptr, old, nsize);
    if (p == nullptr) return nullptr;
    m.used -= old - nsize;
    account.ShrinkHeap(old - nsize);
    return p;
  }
  const size_t grow = nsize - old;
  const size_t retry_of = std::exchange(m.retry_size, 0);  // this call may be the retry
  const uint64_t limit = account.limit();
  const uint64_t after = account.used() + grow;
  bool refuse = limit > 0 && (after > limit + kMemorySlack || after < account.used());
  bool by_run = false;
  if (!refuse && !account.GrowHeap(grow)) refuse = by_run = true;
  if (refuse || (limit > 0 && after > limit)) {
    if (refuse) {
      m.refused_by_run = by_run;
      m.refused_bytes = grow;
      m.retry_block = ptr;
      m.retry_size = nsize;
      // Lua raises LUA_ERRMEM for it, which names no line: where it was
      // asked for is noted now, while the stack is there (ErrorText).
      m.refusal_bytes = grow;
      m.refusal_where[0] = '\0';
      m.refusal_script_line = 0;
      if (heap->L != nullptr && heap->current != nullptr && CanReadStackInAllocator(ptr)) {
        const LuaContext& c = heap->current->context;
        RecordRefusalPlace(*heap->current, c.running != nullptr ? c.running : RootOf(c));
      }
    }
    if (heap->L != nullptr) {
      // Armed on every thread whose hook is another (a callback's budget hook
      // set since would otherwise leave only the hard cap). lua_sethook may
      // be called at any point (even from a signal handler).
      const auto arm = [](lua_State* T) {
        if (lua_gethook(T) != MemoryHook) lua_sethook(T, MemoryHook, LUA_MASKCOUNT, 1);
      };
      arm(heap->L);
      if (heap->current != nullptr)
        for (const Script& script : heap->current->scripts)
          if (script.thread != nullptr) arm(script.thread);
    }
    if (refuse) return nullptr;
  }
  void* p = small_blocks::Resize(ptr, old, nsize);
  if (p == nullptr) {
    account.ShrinkHeap(grow);
    return nullptr;
  }
  m.used += grow;
  // A refusal Lua recovered from fails nothing: its emergency collection
  // freed enough and this is its retry of the same request. The hook raised
  // it anyway (a script whose last step's garbage would have made room
  // failed). A refusal Lua raised stays one pcall cannot catch.
  if (retry_of == nsize && m.retry_block == ptr) m.refused_bytes = 0;
  return p;
}

void ResumeThread(ScriptState* state, Script& script) {
  lua_State* co = script.thread;
  LuaContext& c = state->context;
  const CallInProgress in_progress(*state, kCallbackNames[kThread]);
  MakeCurrent(*state);
  SetCurrent(*state, script);
  SetContext(co, &c);  // its robot's, whoever resumed it last (CheckedCall)
  c.thread = co;
  c.budget_exhausted = false;
  c.data_collected = false;
  c.running = nullptr;
  state->heap->memory.refused_bytes = 0;  // reported with the callback that made it
  state->heap->memory.refusal_bytes = 0;
  c.slice_fires = 0;
  c.slice_yielded = false;
  // A fresh slice. After a yield from the hook, Lua itself left it so: it
  // set the count to 1 and marked the interrupted instruction, which is
  // executed again on resume; that execution resets the count to the slice
  // and, seeing the mark, skips the hook. Resetting the count here would let
  // the mark swallow the next firing instead: two slices in that step.
  if (!script.slice_yielded || lua_gethook(co) != SliceHook ||
      lua_gethookcount(co) != script.slice_instructions)
    lua_sethook(co, SliceHook, LUA_MASKCOUNT, script.slice_instructions);
  int results = 0;
  script.running = true;
  const int status = lua_resume(co, state->L, 0, &results);
  script.running = false;
  c.thread = nullptr;
  script.slice_yielded = c.slice_yielded;
  // A thread its slice switched out step after step never yields by itself:
  // a loop without sim.step, which ran to the end using its slice every
  // step without a word. Said once, in the robot's log.
  if (!c.slice_yielded) {
    script.slice_streak = 0;
  } else if (script.slice_streak < kStuckThreadSteps &&
             ++script.slice_streak == kStuckThreadSteps && c.runtime != nullptr &&
             script.source != nullptr) {
    c.runtime->log.Add(c.log_prefix + "warning: " + script.source->path +
                       ": sysCall_thread has not yielded by itself in " +
                       std::to_string(kStuckThreadSteps) +
                       " steps (its time slice ran out in each): a loop without sim.step() or "
                       "sim.wait()? It goes on, using its slice every step");
  }
  if (status == LUA_YIELD && !c.budget_exhausted) {
    lua_pop(co, results);
    return;
  }
  std::string error;
  if (c.budget_exhausted)
    error = c.budget_error;
  else if (status != LUA_OK)
    error = LocatedErrorText(co, status, script);
  // Finished or failed: the coroutine is not resumed again.
  lua_settop(co, 0);
  luaL_unref(state->L, LUA_REGISTRYINDEX, script.thread_ref);
  script.thread = nullptr;
  script.thread_ref = LUA_NOREF;
  if (!error.empty()) ThrowScriptError(*state, script, std::move(error), "sysCall_thread");
}

}  // namespace lua_host

void FailCallback(lua_State* L) {
  lua_host::ExhaustBudget(L, [&] {
    size_t length = 0;
    const char* message = lua_tolstring(L, -1, &length);
    return message != nullptr ? std::string(message, length) : std::string("refused");
  });
  // ExhaustBudget raises (lua_error does not return, though Lua does not
  // declare it so).
  __builtin_unreachable();
}

}  // namespace swarmsim
