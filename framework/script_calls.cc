// The records of the script calls in progress (script_calls.h).
#include "framework/script_calls.h"

#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "framework/scene.h"

namespace swarmsim::lua_host {
namespace {

std::mutex g_call_records_mutex;
std::vector<CallRecord*>& CallRecords() {
  static auto* records = new std::vector<CallRecord*>;  // leaked on purpose, as the records
  return *records;
}

}  // namespace

CallRecord* NewCallRecord() {
  auto* r = new CallRecord;
  const std::lock_guard lock(g_call_records_mutex);
  CallRecords().push_back(r);
  return r;
}

std::vector<std::string> DescribeCallsInProgress() {
  std::vector<std::string> out;
  const std::lock_guard lock(g_call_records_mutex);
  for (const CallRecord* record : CallRecords()) {
    const ScriptState* state = record->state.load(std::memory_order_acquire);
    if (state == nullptr) continue;
    const Script* script = record->script.load(std::memory_order_relaxed);
    const char* what = record->what.load(std::memory_order_relaxed);
    std::string line = state->context.name;
    if (script != nullptr && script->source != nullptr) line += ": " + script->source->path;
    if (what != nullptr) line += std::string(", in ") + what;
    const Scene& scene = *state->context.scene;
    if (script != nullptr && scene.IsValid(script->object))
      line += " of " + scene.PathOf(script->object);
    out.push_back(std::move(line));
  }
  return out;
}

}  // namespace swarmsim::lua_host
