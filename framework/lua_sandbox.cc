// The libraries a script sees: Lua's base library without file access or
// binary chunks, and string, table, math, coroutine, utf8. No io, os,
// package or debug. (The full sandbox -- instruction budgets, a trusted mode
// -- is a later issue; this opens no holes in the meantime.)
#include <cstring>
#include <initializer_list>

#include "framework/lua_api.h"

namespace swarmsim {
namespace {

// load(chunk [, chunkname [, mode [, env]]]): text chunks only, and by
// default in the calling script's environment rather than the shared
// globals, so a loaded chunk cannot leak globals into other scripts.
int SafeLoad(lua_State* L) {
  const int n = lua_gettop(L);
  lua_settop(L, 4);
  lua_pushliteral(L, "t");
  lua_replace(L, 3);
  if (n < 4) {
    lua_rawgeti(L, LUA_REGISTRYINDEX, Context(L).script_env_ref);
    lua_replace(L, 4);
  }
  lua_pushvalue(L, lua_upvalueindex(1));  // the original load
  lua_insert(L, 1);
  lua_call(L, 4, LUA_MULTRET);
  return lua_gettop(L);
}

// collectgarbage([opt [, ...]]): only the options that cannot change how the
// collector runs for the other scripts of the state.
int SafeCollectGarbage(lua_State* L) {
  static const char* const kAllowed[] = {"collect", "count", "step", "isrunning", nullptr};
  luaL_checkoption(L, 1, "collect", kAllowed);
  lua_pushvalue(L, lua_upvalueindex(1));  // the original collectgarbage
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
  return lua_gettop(L);
}

// Replaces the global table `name` (and its package.loaded entry) by a copy
// without the `dropped` fields, sized for what is left: a table's hash part
// never shrinks, and every robot's state carries it.
void Compact(lua_State* L, const char* name, std::initializer_list<const char*> dropped) {
  lua_getglobal(L, name);
  const int old = lua_gettop(L);
  int kept = 0;
  for (lua_pushnil(L); lua_next(L, old) != 0; lua_pop(L, 1)) ++kept;
  lua_createtable(L, 0, kept - static_cast<int>(dropped.size()));
  for (lua_pushnil(L); lua_next(L, old) != 0; lua_pop(L, 1)) {
    bool drop = false;
    for (const char* field : dropped)
      drop =
          drop || (lua_type(L, -2) == LUA_TSTRING && std::strcmp(lua_tostring(L, -2), field) == 0);
    if (drop) continue;
    lua_pushvalue(L, -2);
    lua_pushvalue(L, -2);
    lua_rawset(L, -5);
  }
  lua_pushvalue(L, -1);
  lua_setglobal(L, name);
  lua_getfield(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  lua_insert(L, -2);
  lua_setfield(L, -2, name);
  lua_settop(L, old - 1);
}

void Wrap(lua_State* L, const char* name, lua_CFunction wrapper) {
  lua_getglobal(L, name);
  lua_pushcclosure(L, wrapper, 1);
  lua_setglobal(L, name);
}

}  // namespace

void OpenSafeLibraries(lua_State* L) {
  static constexpr luaL_Reg kLibraries[] = {
      {LUA_GNAME, luaopen_base},       {LUA_COLIBNAME, luaopen_coroutine},
      {LUA_TABLIBNAME, luaopen_table}, {LUA_STRLIBNAME, luaopen_string},
      {LUA_MATHLIBNAME, luaopen_math}, {LUA_UTF8LIBNAME, luaopen_utf8},
  };
  for (const luaL_Reg& library : kLibraries) {
    luaL_requiref(L, library.name, library.func, 1);
    lua_pop(L, 1);
  }
  // No file access, no writing to the process's stderr.
  for (const char* name : {"dofile", "loadfile", "warn"}) {
    lua_pushnil(L);
    lua_setglobal(L, name);
  }
  Wrap(L, "load", SafeLoad);
  Wrap(L, "collectgarbage", SafeCollectGarbage);
  // string.dump makes binary chunks, which nothing here can load. Strings'
  // methods ("abc"):upper() come from the new table too.
  Compact(L, LUA_STRLIBNAME, {"dump"});
  lua_pushliteral(L, "");
  lua_getmetatable(L, -1);
  lua_getglobal(L, LUA_STRLIBNAME);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 2);
  // Debian builds Lua with LUA_COMPAT_MATHLIB: functions 5.4 deprecated, and
  // 35 entries need a 64-slot table where 28 fit in 32 (~0.5 KB per robot).
  Compact(L, LUA_MATHLIBNAME, {"cosh", "sinh", "tanh", "pow", "frexp", "ldexp", "log10"});
}

}  // namespace swarmsim
