// ArgBytes (lua_bytes.h).
#include "framework/lua_bytes.h"

#include "framework/error.h"
#include "lua.hpp"

namespace swarmsim {

namespace {

// A key of the table at `index` that is not one of 1..n, described for a
// message ("" if every key is one of them). Walks the whole table.
std::string StrayKey(lua_State* L, int index, lua_Integer n) {
  lua_pushnil(L);
  while (lua_next(L, index) != 0) {
    lua_pop(L, 1);  // the value
    int is_integer = 0;
    const lua_Integer k = lua_type(L, -1) == LUA_TNUMBER ? lua_tointegerx(L, -1, &is_integer) : 0;
    if (!is_integer || k < 1 || k > n) {
      std::string key;  // appended: GCC 12 warns on "lit" + std::string chains (-Wrestrict)
      if (is_integer) {
        key += '[';
        key += std::to_string(k);
        key += ']';
      } else if (lua_type(L, -1) == LUA_TSTRING) {
        key += '\'';
        key += lua_tostring(L, -1);
        key += '\'';
      } else {
        key += "a ";
        key += luaL_typename(L, -1);
      }
      lua_pop(L, 1);
      return key;
    }
  }
  return "";
}

}  // namespace

std::vector<uint8_t> ArgBytes(lua_State* L, int arg, size_t max, const char* what,
                              const std::function<std::string(size_t)>& too_long) {
  std::vector<uint8_t> data;
  if (lua_type(L, arg) == LUA_TSTRING) {
    size_t length = 0;
    const char* bytes = lua_tolstring(L, arg, &length);
    if (length > max) throw Error(too_long(length));
    data.assign(bytes, bytes + length);
    return data;
  }
  if (lua_type(L, arg) != LUA_TTABLE)
    throw Error("bad argument #" + std::to_string(arg) +
                " (a string of bytes or a table of integers 0..255 expected, got " +
                luaL_typename(L, arg) + ")");
  const int table = lua_absindex(L, arg);
  // Element by element up to the first nil; one past `max` is enough to
  // refuse (the rest counted for the message, up to a bound).
  data.reserve(max);
  lua_Integer i = 1;
  for (;; ++i) {
    const int type = lua_rawgeti(L, table, i);
    if (type == LUA_TNIL) {
      lua_pop(L, 1);
      break;
    }
    int is_integer = 0;
    const lua_Integer v = lua_tointegerx(L, -1, &is_integer);
    lua_pop(L, 1);
    if (type != LUA_TNUMBER || !is_integer || v < 0 || v > 255)
      throw Error("element " + std::to_string(i) + " of the " + what +
                  " must be an integer from 0 to 255 (a byte)");
    if (static_cast<size_t>(i) > max) {
      lua_Integer n = i;
      while (n < i + 1000000 && lua_rawgeti(L, table, n + 1) != LUA_TNIL) {
        lua_pop(L, 1);
        ++n;
      }
      lua_pop(L, 1);
      throw Error(too_long(static_cast<size_t>(n)));
    }
    data.push_back(static_cast<uint8_t>(v));
  }
  const lua_Integer n = i - 1;
  if (const std::string key = StrayKey(L, table, n); !key.empty())
    throw Error(
        "the " + std::string(what) + " table has key " + key +
        (n == 0 ? " but no t[1]" : " besides its bytes t[1]..t[" + std::to_string(n) + "]") +
        ": a table of bytes is a sequence with no hole (nil is no byte: write 0) and "
        "no other keys");
  return data;
}

}  // namespace swarmsim
