// The sandbox's lazy standard libraries (lua_libraries.h).
#include "framework/lua_libraries.h"

#include <algorithm>
#include <new>

#include "framework/error.h"

namespace swarmsim {
namespace sandbox {
namespace {
// __index of a lazy library table (upvalue 1: its LazyLibrary): fetch the
// entry, keep it in the table. A missing field is nil as usual, except the
// one refused by name.
int LazyLibraryIndex(lua_State* L) {
  const auto& library = *static_cast<const LazyLibrary*>(lua_touserdata(L, lua_upvalueindex(1)));
  if (lua_type(L, 2) != LUA_TSTRING) return 0;
  const std::string_view key = lua_tostring(L, 2);
  if (const LibraryEntry* entry = FindEntry(library, key)) return KeepEntry(L, *entry);
  if (library.refused != nullptr && key == library.refused)
    Refuse(L, std::string(library.name) + "." + library.refused);
  return 0;
}
}  // namespace

LazyLibrary ReadLibrary(const char* name, lua_CFunction open,
                        std::initializer_list<const char*> dropped, const char* refused) {
  LazyLibrary library;
  library.name = name;
  library.refused = refused;
  lua_State* L = luaL_newstate();
  if (L == nullptr) throw std::bad_alloc();
  luaL_requiref(L, name, open, 0);
  for (lua_pushnil(L); lua_next(L, -2) != 0; lua_pop(L, 1)) {
    if (lua_type(L, -2) != LUA_TSTRING) continue;
    LibraryEntry e;
    e.name = lua_tostring(L, -2);
    const bool drop = std::any_of(dropped.begin(), dropped.end(),
                                  [&](const char* field) { return e.name == field; });
    e.type = lua_type(L, -1);
    if (drop || e.name == (refused != nullptr ? refused : "")) continue;
    if (e.type == LUA_TFUNCTION) {
      if (!lua_iscfunction(L, -1)) continue;
      if (lua_getupvalue(L, -1, 1) != nullptr) {  // its own state's (math.random's generator)
        lua_pop(L, 1);
        continue;
      }
      e.function = lua_tocfunction(L, -1);
    } else if (e.type == LUA_TNUMBER) {
      e.is_integer = lua_isinteger(L, -1);
      e.integer = lua_tointeger(L, -1);
      e.number = lua_tonumber(L, -1);
    } else {
      continue;
    }
    library.entries.push_back(std::move(e));
  }
  lua_close(L);
  std::sort(library.entries.begin(), library.entries.end(),
            [](const LibraryEntry& a, const LibraryEntry& b) { return a.name < b.name; });
  return library;
}

const LibraryEntry* FindEntry(const LazyLibrary& library, std::string_view key) {
  const auto it =
      std::lower_bound(library.entries.begin(), library.entries.end(), key,
                       [](const LibraryEntry& e, std::string_view k) { return e.name < k; });
  return it == library.entries.end() || it->name != key ? nullptr : &*it;
}

// Pushes the entry, and keeps it in the table at index 1 under the key at
// index 2 (an __index call's arguments).
int KeepEntry(lua_State* L, const LibraryEntry& entry) {
  switch (entry.type) {
    case LUA_TFUNCTION: lua_pushcfunction(L, entry.function); break;
    case LUA_TNUMBER:
      if (entry.is_integer)
        lua_pushinteger(L, entry.integer);
      else
        lua_pushnumber(L, entry.number);
      break;
    default: return 0;
  }
  lua_pushvalue(L, 2);
  lua_pushvalue(L, -2);
  lua_rawset(L, 1);
  return 1;
}

// The base library's functions, fetched into the globals on first use
// (SandboxGlobalIndex), but for those the sandbox replaces or removes.
const LazyLibrary& BaseLibrary() {
  static const LazyLibrary base = ReadLibrary(
      LUA_GNAME, luaopen_base,
      {"load", "setmetatable", "collectgarbage", "dofile", "loadfile", "warn", "print"}, nullptr);
  return base;
}
// Lua's own load and collectgarbage, which the sandbox wraps.
lua_CFunction BaseFunction(const char* name) {
  static const LazyLibrary all = ReadLibrary(LUA_GNAME, luaopen_base, {}, nullptr);
  const LibraryEntry* entry = FindEntry(all, name);
  SWARMSIM_CHECK(entry != nullptr && entry->function != nullptr, "Lua's base library changed");
  return entry->function;
}

// Makes the global table `library.name` (and its package.loaded entry) an
// empty table that fetches each entry of `library` on first use, and leaves
// it on the stack: every robot's state carries its libraries, and a script
// uses a few of their functions (math: 7 of 28 in diffusion.lua; ~3 KB per
// robot less for math, string and table). The library is never opened in
// the robot's state (that would build its full table, then drop it): what
// opening it leaves besides its entries comes from LibraryExtras. `pairs(math)`
// lists what the robot has used so far. `fields`: those the caller adds.
void OpenLazy(lua_State* L, const LazyLibrary& library, int fields) {
  lua_createtable(L, 0, fields);
  lua_createtable(L, 0, 1);
  lua_pushlightuserdata(L, const_cast<LazyLibrary*>(&library));
  lua_pushcclosure(L, (Guarded<LazyLibraryIndex, "">), 1);
  lua_setfield(L, -2, "__index");
  lua_setmetatable(L, -2);
  lua_pushvalue(L, -1);
  lua_setglobal(L, library.name);
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  lua_pushvalue(L, -2);
  lua_setfield(L, -2, library.name);
  lua_pop(L, 1);
}

const LibraryExtras& Extras() {
  static const LibraryExtras extras = [] {
    LibraryExtras e;
    lua_State* L = luaL_newstate();
    if (L == nullptr) throw std::bad_alloc();
    luaL_requiref(L, LUA_STRLIBNAME, luaopen_string, 0);
    lua_pushliteral(L, "");
    SWARMSIM_CHECK(lua_getmetatable(L, -1) != 0, "Lua's string library set no metatable");
    for (lua_pushnil(L); lua_next(L, -2) != 0; lua_pop(L, 1)) {
      if (lua_type(L, -2) != LUA_TSTRING || !lua_iscfunction(L, -1)) continue;  // __index
      SWARMSIM_CHECK(lua_getupvalue(L, -1, 1) == nullptr, "a string metamethod has an upvalue");
      e.string_metamethods.emplace_back(lua_tostring(L, -2), lua_tocfunction(L, -1));
    }
    std::sort(e.string_metamethods.begin(), e.string_metamethods.end());
    lua_settop(L, 0);
    luaL_requiref(L, LUA_MATHLIBNAME, luaopen_math, 0);
    lua_getfield(L, 1, "random");
    lua_getfield(L, 1, "randomseed");
    e.random = lua_tocfunction(L, 2);
    e.randomseed = lua_tocfunction(L, 3);
    // Each with one upvalue, the same generator (pushed at 4 and 5).
    const bool one_upvalue_each = lua_getupvalue(L, 2, 1) != nullptr &&
                                  lua_getupvalue(L, 3, 1) != nullptr &&
                                  lua_getupvalue(L, 2, 2) == nullptr;
    SWARMSIM_CHECK(e.random != nullptr && e.randomseed != nullptr && one_upvalue_each &&
                       lua_type(L, 4) == LUA_TUSERDATA && lua_rawequal(L, 4, 5),
                   "Lua's math.random changed");
    e.generator_bytes = lua_rawlen(L, 4);
    lua_close(L);
    return e;
  }();
  return extras;
}

// Replaces field `name` of the table at `table` with `wrapper`, which gets
// the original as its upvalue 1.
void WrapField(lua_State* L, int table, const char* name, lua_CFunction wrapper) {
  table = lua_absindex(L, table);
  lua_getfield(L, table, name);
  lua_pushcclosure(L, wrapper, 1);
  lua_setfield(L, table, name);
}

[[noreturn]] void Refuse(lua_State* L, const std::string& what) {
  RaiseRefusal(L, what +
                      " is not allowed in a sandboxed script (run with --trust-scripts to lift "
                      "the sandbox)");
}

}  // namespace sandbox

void* PinRandomGenerator(lua_State* L, size_t* bytes) {
  void* generator = nullptr;
  lua_getglobal(L, LUA_MATHLIBNAME);
  if (lua_type(L, -1) == LUA_TTABLE) {
    lua_pushliteral(L, "random");
    lua_rawget(L, -2);
    if (lua_tocfunction(L, -1) != nullptr && lua_getupvalue(L, -1, 1) != nullptr) {
      if (lua_type(L, -1) == LUA_TUSERDATA) {
        *bytes = lua_rawlen(L, -1);
        generator = lua_touserdata(L, -1);
        lua_pushvalue(L, -1);
        luaL_ref(L, LUA_REGISTRYINDEX);
      }
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  return generator;
}

}  // namespace swarmsim
