// The errors of the Lua host: their text, and what a failing script does
// under on_script_error.
#include "framework/script_state.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/utf8.h"
#include "framework/world.h"

namespace swarmsim::lua_host {
namespace {

// Stack levels looked at for an error's place: it is raised near the top,
// and lua_getstack walks from there (a deep recursion must not cost more).
constexpr int kLevelsSearched = 100;

// Does `text` start with a position, "name:line:" as luaL_where makes it
// (a chunk name "[string \"...\"]" may hold colons of its own)?
bool HasPosition(const char* text, size_t length) {
  const size_t end = std::min<size_t>(length, 1024);
  size_t i = 0;
  if (end > 0 && text[0] == '[')
    while (i < end && text[i] != ']') ++i;
  while (i < end && text[i] != ':' && text[i] != '\n') ++i;
  if (i == 0 || i >= end || text[i] != ':') return false;
  size_t j = i + 1;
  while (j < end && text[j] >= '0' && text[j] <= '9') ++j;
  return j > i + 1 && j < end && text[j] == ':';
}

// Does `text` start with "<file>:"?
bool StartsWithFile(const char* text, size_t length, const std::string& file) {
  return !file.empty() && length > file.size() && text[file.size()] == ':' &&
         std::memcmp(text, file.data(), file.size()) == 0;
}

// Where an error was raised: the innermost Lua function with a line, and
// the innermost line of the running script's own file, from stack level
// `level` of L outwards. Plain data: the message handler builds no C++
// object (a Lua error may jump out of it).
struct ErrorPlace {
  char where[LUA_IDSIZE + 32] = "";  // "file:line: ", or ""
  int script_line = 0;               // 0: no function of the script's file
};
ErrorPlace FindErrorPlace(lua_State* L, int level, const std::string* file) {
  ErrorPlace place;
  lua_Debug ar;
  for (int n = 0; n < kLevelsSearched && lua_getstack(L, level, &ar) != 0; ++n, ++level) {
    if (lua_getinfo(L, "Sl", &ar) == 0 || ar.currentline <= 0) continue;
    if (place.where[0] == '\0')
      std::snprintf(place.where, sizeof place.where, "%s:%d: ", ar.short_src, ar.currentline);
    if (file != nullptr && ar.source[0] == '@' && *file == ar.source + 1) {
      place.script_line = ar.currentline;
      break;
    }
  }
  return place;
}

const std::string* ScriptFile(const Script* script) {
  return script != nullptr && script->source != nullptr && !script->source->path.empty()
             ? &script->source->path
             : nullptr;
}

}  // namespace

std::string FormatBytes(uint64_t bytes) {
  char text[32];
  if (bytes >= (uint64_t{1} << 30))
    std::snprintf(text, sizeof text, "%.1f GiB", static_cast<double>(bytes) / (1 << 30));
  else if (bytes >= (uint64_t{1} << 20))
    std::snprintf(text, sizeof text, "%llu MiB", static_cast<unsigned long long>(bytes >> 20));
  else
    std::snprintf(text, sizeof text, "%llu KiB",
                  static_cast<unsigned long long>((bytes + 1023) >> 10));
  return text;
}

ScriptState::~ScriptState() {
  if (L == nullptr) return;
  std::unique_lock<std::mutex> lock(heap->mutex, std::defer_lock);
  if (heap->shared) lock.lock();
  if (context.may_finalize) heap->may_finalize = true;
  if (heap.use_count() > 1) {
    // Other robots go on in the state: this one's references go (its
    // environments and functions become garbage). The heap outlives the
    // lock: the robots still holding it wait for the mutex.
    for (Script& script : scripts) {
      luaL_unref(L, LUA_REGISTRYINDEX, script.env_ref);
      luaL_unref(L, LUA_REGISTRYINDEX, script.thread_ref);
      for (int& ref : script.callbacks) luaL_unref(L, LUA_REGISTRYINDEX, ref);
    }
    if (heap->current == this) heap->current = nullptr;
    heap.reset();
    return;
  }
  if (heap->leave_to_system && !heap->may_finalize) return;  // the process ends
  // Finalizers (a file io opened) run with this robot's context.
  heap->current = this;
  SetContext(L, &context);
  lua_close(L);
  heap->L = nullptr;
}

void MakeCurrent(ScriptState& state) {
  LuaHeap& heap = *state.heap;
  if (heap.current == &state) return;
  if (heap.generator != nullptr) {
    if (heap.current != nullptr)
      std::memcpy(heap.current->generator, heap.generator, kGeneratorBytes);
    std::memcpy(heap.generator, state.generator, kGeneratorBytes);
  }
  heap.current = &state;
  SetContext(state.L, &state.context);
}

std::string MemoryLimitTail(const LuaMemory& memory) {
  const ScriptMemory& account = *memory.account;
  const std::string limit = std::to_string(account.limit() >> 20) + " MiB";
  if (account.data() == 0) return limit + " of Lua memory (" + memory.setting + ")";
  return limit + " (" + FormatBytes(account.used() - account.data()) + " of Lua memory and " +
         FormatBytes(account.data()) +
         " of data the sim.* calls keep for them: signals, custom data, messages, prints, "
         "metrics; " +
         memory.setting + ")";
}

std::string RunLimitTail(const ScriptMemory& account) {
  const RunScriptMemory* run = account.run();
  return "the run's scripts past " + std::to_string(run != nullptr ? run->limit() >> 20 : 0) +
         " MiB (simulation.run_script_memory_mb: every robot's Lua memory and data together)";
}

void RecordRefusalPlace(ScriptState& state, lua_State* running) {
  LuaMemory& m = state.heap->memory;
  const auto* script = static_cast<const Script*>(state.context.host_script);
  const ErrorPlace place = FindErrorPlace(running, 0, ScriptFile(script));
  std::memcpy(m.refusal_where, place.where, sizeof m.refusal_where);
  m.refusal_where[sizeof m.refusal_where - 1] = '\0';
  m.refusal_script_line = place.script_line;
  m.refusal_script = script;
}

std::string RefusalText(const ScriptState& state) {
  const LuaMemory& m = state.heap->memory;
  std::string text = m.refusal_where;
  const std::string* file = ScriptFile(m.refusal_script);
  if (file != nullptr && m.refusal_script_line > 0 &&
      !StartsWithFile(text.data(), text.size(), *file))
    text.insert(0, *file + ":" + std::to_string(m.refusal_script_line) + ": ");
  return text + "an allocation of " + FormatBytes(m.refusal_bytes) + " would take " +
         (m.refused_by_run ? RunLimitTail(*m.account)
                           : m.holder + std::string(" past ") + MemoryLimitTail(m));
}

std::string ErrorText(lua_State* L, int status) {
  if (status == LUA_ERRMEM) {
    // Lua raised it for a refusal (its stack unwound by now): the place
    // LimitedAlloc noted.
    const auto* state = static_cast<const ScriptState*>(Context(L).host_state);
    if (state == nullptr || state->heap->memory.refusal_bytes == 0) return "not enough memory";
    return RefusalText(*state);
  }
  if (status != LUA_ERRRUN && status != LUA_ERRSYNTAX && status != LUA_ERRERR)
    return "internal error: a C++ exception crossed a Lua frame (please report this)";
  if (lua_type(L, -1) == LUA_TSTRING) {
    // Whole, also past a NUL byte (shown as \0: a C string would end there),
    // its terminal controls escaped (an error('\27[2J') cleared the console).
    size_t length = 0;
    const char* text = lua_tolstring(L, -1, &length);
    return EscapeControls(std::string_view(text, length));
  }
  return std::string("(error object is a ") + luaL_typename(L, -1) + " value)";
}

int LocateError(lua_State* L) {
  const std::string* file = ScriptFile(static_cast<const Script*>(Context(L).host_script));
  const int value = lua_gettop(L);
  if (lua_type(L, value) != LUA_TSTRING) {
    lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, value));
    lua_replace(L, value);
  }
  size_t length = 0;
  const char* text = lua_tolstring(L, value, &length);
  const ErrorPlace place = FindErrorPlace(L, 1, file);
  // The message as it starts once located.
  const bool add_where = !HasPosition(text, length) && place.where[0] != '\0';
  const char* start = add_where ? place.where : text;
  const size_t start_length = add_where ? std::strlen(place.where) : length;
  int pieces = 1;
  if (file != nullptr && place.script_line > 0 && !StartsWithFile(start, start_length, *file)) {
    lua_pushfstring(L, "%s:%d: ", file->c_str(), place.script_line);
    ++pieces;
  }
  if (add_where) {
    lua_pushstring(L, place.where);
    ++pieces;
  }
  lua_pushvalue(L, value);
  lua_concat(L, pieces);
  return 1;
}

std::string LocatedErrorText(lua_State* co, int status, const Script& script) {
  std::string text = ErrorText(co, status);
  if (status != LUA_ERRRUN && status != LUA_ERRERR) return text;
  const std::string* file = ScriptFile(&script);
  const ErrorPlace place = FindErrorPlace(co, 0, file);
  if (!HasPosition(text.data(), text.size())) text.insert(0, place.where);
  if (file != nullptr && place.script_line > 0 && !StartsWithFile(text.data(), text.size(), *file))
    text.insert(0, *file + ":" + std::to_string(place.script_line) + ": ");
  return text;
}

void ThrowScriptError(const ScriptState& state, const Script& script, std::string message,
                      std::string_view what) {
  lua_settop(state.L, 0);
  const Scene& scene = *state.context.scene;
  const std::string path = scene.IsValid(script.object) ? scene.PathOf(script.object)
                           : state.context.is_main      ? std::string("the main script")
                                                        : std::string("?");
  // The script is named whatever the message says (a module's line, none).
  if (const std::string* file = ScriptFile(&script);
      file != nullptr && !StartsWithFile(message.data(), message.size(), *file))
    message.insert(0, *file + ": ");
  const std::string head = state.context.name + ": ";
  const std::string tail = " [in " + std::string(what) + " of " + path + "]";
  // Cut so that the whole text fits: the tail names where it happened.
  const size_t room = kMaxErrorTextBytes > head.size() + tail.size() + 256
                          ? kMaxErrorTextBytes - head.size() - tail.size()
                          : 256;
  throw Error(head + CutErrorText(message, room) + tail);
}

bool Disable(ScriptState& state, Script& script, const std::string& error) {
  if (state.context.world->settings().on_script_error != ScriptErrorPolicy::kDisableScript ||
      state.context.is_main)
    return false;
  script.disabled = true;
  std::string text = CutErrorText(error);
  state.context.runtime->log.Add("error, script disabled: " + text);
  state.context.runtime->disabled.push_back(std::move(text));
  return true;
}

}  // namespace swarmsim::lua_host

namespace swarmsim {

void ChargeScriptData(lua_State* L, uint64_t bytes, const char* what) {
  LuaContext& c = Context(L);
  ScriptMemory* account = c.memory;
  if (account == nullptr) return;
  ScriptMemory::Result result = account->Charge(bytes);
  if (result != ScriptMemory::kOk && !c.data_collected) {
    // Garbage first, as for the Lua heap; once per callback (a pcall loop
    // around a refused call must not cost a full collection each time).
    c.data_collected = true;
    lua_gc(L, LUA_GCCOLLECT);
    result = account->Charge(bytes);
  }
  if (result == ScriptMemory::kOk) return;
  const auto* state = static_cast<const lua_host::ScriptState*>(c.host_state);
  if (result == ScriptMemory::kPastRunLimit || state == nullptr)
    throw Error(std::string(what) + " would take " + lua_host::RunLimitTail(*account));
  if (state->heap->shared)  // the robot's account holds its data only (its heap is the state's)
    throw Error(std::string(what) + " would take the data the sim.* calls keep for " + c.name +
                " past " + std::to_string(account->limit() >> 20) +
                " MiB (simulation.script_memory_mb; raise it if the data is real)");
  throw Error(std::string(what) + " would take " + state->heap->memory.holder + " past " +
              lua_host::MemoryLimitTail(state->heap->memory));
}

void CallCharge::Grow(uint64_t bytes) {
  ScriptMemory* account = Context(L_).memory;
  if (account == nullptr) return;
  // A quarter ahead (at least 64 KiB) if that fits, else the bytes themselves.
  const uint64_t extra = std::max<uint64_t>(bytes / 4, uint64_t{64} << 10);
  const uint64_t ahead = bytes <= UINT64_MAX - extra ? bytes + extra : bytes;
  if (account->Charge(ahead - held_) == ScriptMemory::kOk) {
    held_ = ahead;
    return;
  }
  ChargeScriptData(L_, bytes - held_, what_);  // throws if they do not fit
  held_ = bytes;
}

CallCharge::~CallCharge() {
  if (held_ > 0) Context(L_).memory->Release(held_);
}

}  // namespace swarmsim
