// Internal to the Lua host (script_*.cc, lua_api_control.cc): the script
// calls in progress, process-wide, for ScriptCallsInProgress (script_host.h).
//
// Each thread that runs scripts keeps a record of the innermost call it is
// in. The records are never freed (a thread may end; its record stays, idle),
// so a watchdog can read them at any time.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "framework/script_state.h"

namespace swarmsim::lua_host {

struct CallRecord {
  std::atomic<const ScriptState*> state{nullptr};
  std::atomic<const Script*> script{nullptr};
  std::atomic<const char*> what{nullptr};
};

// A new record, listed for DescribeCallsInProgress (never freed).
CallRecord* NewCallRecord();

// The calling thread's record.
inline CallRecord& ThisThreadsRecord() {
  thread_local CallRecord* record = NewCallRecord();
  return *record;
}

// Marks the calling thread as running `what` of a script of `state` for the
// scope's duration (SetCurrent names the script); restores the outer call.
class CallInProgress {
 public:
  CallInProgress(const ScriptState& state, const char* what)
      : record_(ThisThreadsRecord()),
        state_(record_.state.load(std::memory_order_relaxed)),
        script_(record_.script.load(std::memory_order_relaxed)),
        what_(record_.what.load(std::memory_order_relaxed)) {
    record_.what.store(what, std::memory_order_relaxed);
    record_.state.store(&state, std::memory_order_release);
  }
  ~CallInProgress() {
    record_.state.store(state_, std::memory_order_relaxed);
    record_.script.store(script_, std::memory_order_relaxed);
    record_.what.store(what_, std::memory_order_relaxed);
  }
  CallInProgress(const CallInProgress&) = delete;
  CallInProgress& operator=(const CallInProgress&) = delete;

 private:
  CallRecord& record_;
  const ScriptState* state_;
  const Script* script_;
  const char* what_;
};

// Makes `script` the one its state runs: for the sim.* functions (the
// context's script fields) and for the calling thread's record.
inline void SetCurrent(ScriptState& state, Script& script) {
  state.context.script_object = script.object;
  state.context.script_env_ref = script.env_ref;
  state.context.mailbox = &script.mailbox;
  state.context.host_script = &script;
  ThisThreadsRecord().script.store(&script, std::memory_order_relaxed);
}

// ScriptCallsInProgress (script_host.h): one line per thread in a call.
std::vector<std::string> DescribeCallsInProgress();

}  // namespace swarmsim::lua_host
