// Internal to the sandbox (lua_sandbox.cc): the safe standard libraries as
// lazy tables. Each library's entries that need nothing of the state they
// live in are read once per process from a scratch state; a robot's state
// gets an empty table per library that fetches an entry on first use
// (OpenLazy), so a robot pays only for the functions its scripts use.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/lua_api.h"

namespace swarmsim::sandbox {

// A standard library's entries that need nothing of the state they live in
// (C functions without upvalues, and numbers), read once per process from a
// scratch state, sorted by name.
struct LibraryEntry {
  std::string name;
  int type = LUA_TNIL;
  lua_CFunction function = nullptr;
  bool is_integer = false;
  lua_Integer integer = 0;
  lua_Number number = 0;
};
struct LazyLibrary {
  std::vector<LibraryEntry> entries;
  const char* refused = nullptr;  // a field refused by name ("dump" of string), or null
  const char* name = "";
};

// `name`'s entries (opened by `open` in a scratch state), but `dropped`
// and the field `refused` by name (or null).
LazyLibrary ReadLibrary(const char* name, lua_CFunction open,
                        std::initializer_list<const char*> dropped, const char* refused);

// The entry `key` of `library`, or null.
const LibraryEntry* FindEntry(const LazyLibrary& library, std::string_view key);

// Pushes the entry, and keeps it in the table at index 1 under the key at
// index 2 (an __index call's arguments). Returns the results pushed.
int KeepEntry(lua_State* L, const LibraryEntry& entry);

// The base library's functions, fetched into the globals on first use
// (SandboxGlobalIndex), but for those the sandbox replaces or removes.
const LazyLibrary& BaseLibrary();
// Lua's own base function `name` (load, collectgarbage: the sandbox wraps them).
lua_CFunction BaseFunction(const char* name);

// Makes the global table `library.name` (and its package.loaded entry) an
// empty table that fetches each entry of `library` on first use, and leaves
// it on the stack. `fields`: those the caller adds.
void OpenLazy(lua_State* L, const LazyLibrary& library, int fields);

// What opening string and math leaves in a state besides their tables'
// entries, read once per process from a scratch state: the metamethods of
// the strings' metatable (arithmetic on numeric strings: "10" + 1), and
// math.random and math.randomseed, C functions sharing one upvalue (the
// generator, a userdata of `generator_bytes`).
struct LibraryExtras {
  std::vector<std::pair<std::string, lua_CFunction>> string_metamethods;  // all but __index
  lua_CFunction random = nullptr;
  lua_CFunction randomseed = nullptr;
  size_t generator_bytes = 0;
};
const LibraryExtras& Extras();

// Replaces field `name` of the table at `table` with `wrapper`, which gets
// the original as its upvalue 1.
void WrapField(lua_State* L, int table, const char* name, lua_CFunction wrapper);

// Raises "<what> is not allowed in a sandboxed script (...)", ending the
// running callback (RaiseRefusal).
[[noreturn]] void Refuse(lua_State* L, const std::string& what);

}  // namespace swarmsim::sandbox
