// LimitedLua (framework/lua_evaluator.cc): the loader's "= expression"
// values run under the host's own limits, so an endless or greedy
// expression in a world file is an error naming the limit, never a hang.
#include "framework/lua_evaluator.h"

#include <gtest/gtest.h>

#include <string>

#include "framework/lua_api.h"  // lua.hpp
#include "tests/framework/error_of.h"

namespace swarmsim {
namespace {

constexpr size_t kMemoryLimit = size_t{4} << 20;
constexpr int64_t kBudget = 100000;

// Loads `code` as chunk "expr" and calls it for one result: true, or false
// with the error in *error.
bool Evaluate(LimitedLua* lua, const std::string& code, std::string* error) {
  lua_State* L = lua->L();
  if (luaL_loadbuffer(L, code.data(), code.size(), "=expr") != LUA_OK) {
    *error = lua_tostring(L, -1);
    lua_pop(L, 1);
    return false;
  }
  return lua->Call(0, 1, error);
}

TEST(LimitedLuaTest, EvaluatesAnExpression) {
  LimitedLua lua("the expression", kMemoryLimit, kBudget);
  std::string error;
  ASSERT_TRUE(Evaluate(&lua, "return 2 * 21 + 0.5", &error)) << error;
  EXPECT_EQ(lua_tonumber(lua.L(), -1), 42.5);
  lua_pop(lua.L(), 1);
  // No library is open: the expression sees nothing it was not given.
  ASSERT_TRUE(Evaluate(&lua, "return os == nil and io == nil and print == nil", &error)) << error;
  EXPECT_TRUE(lua_toboolean(lua.L(), -1));
}

TEST(LimitedLuaTest, AnEndlessLoopIsAnErrorNamingTheSubjectAndTheLine) {
  LimitedLua lua("the expression", kMemoryLimit, kBudget);
  std::string error;
  EXPECT_FALSE(Evaluate(&lua, "local x = 1\nwhile true do x = x + 1 end", &error));
  EXPECT_EQ(error,
            "expr:2: the expression ran more than 100000 Lua instructions without returning "
            "(an endless loop?)");
  EXPECT_EQ(lua_gettop(lua.L()), 0);  // the stack is emptied
}

TEST(LimitedLuaTest, PcallCannotCatchTheSpentBudget) {
  LimitedLua lua("the expression", kMemoryLimit, kBudget);
  luaL_requiref(lua.L(), "_G", luaopen_base, 1);
  lua_pop(lua.L(), 1);
  std::string error;
  EXPECT_FALSE(Evaluate(&lua, "pcall(function() while true do end end)\nreturn 'went on'", &error));
  EXPECT_CONTAINS(error, "the expression ran more than 100000 Lua instructions");
}

// Each call gets the whole budget again; a failed call leaves the state usable.
TEST(LimitedLuaTest, EachCallHasAFreshBudget) {
  LimitedLua lua("the expression", kMemoryLimit, kBudget);
  std::string error;
  const std::string loop = "local n = 0\nfor i = 1, 30000 do n = n + i end\nreturn n";
  for (int call = 0; call < 5; ++call) {  // 5 x 30,000 turns: more than one budget in all
    ASSERT_TRUE(Evaluate(&lua, loop, &error)) << "call " << call << ": " << error;
    EXPECT_EQ(lua_tointeger(lua.L(), -1), 30000LL * 30001 / 2);
    lua_pop(lua.L(), 1);
  }
  EXPECT_FALSE(Evaluate(&lua, "while true do end", &error));
  ASSERT_TRUE(Evaluate(&lua, loop, &error)) << error;
}

TEST(LimitedLuaTest, TooMuchMemoryIsAnErrorNamingTheLimit) {
  LimitedLua lua("the expression", kMemoryLimit, int64_t{1} << 40);
  std::string error;
  EXPECT_FALSE(Evaluate(&lua, "local t = {}\nfor i = 1, 1e8 do t[i] = i end\nreturn #t", &error));
  EXPECT_CONTAINS(error, "the expression");
  EXPECT_CONTAINS(error, "4 MiB of Lua memory (the limit of one evaluation)");
  // The memory is given back: the next evaluation runs.
  ASSERT_TRUE(Evaluate(&lua, "local t = {}\nfor i = 1, 1000 do t[i] = i end\nreturn #t", &error))
      << error;
  EXPECT_EQ(lua_tointeger(lua.L(), -1), 1000);
}

TEST(LimitedLuaTest, ARuntimeErrorKeepsLuasMessage) {
  LimitedLua lua("the expression", kMemoryLimit, kBudget);
  std::string error;
  EXPECT_FALSE(Evaluate(&lua, "local a\nreturn a + 1", &error));
  EXPECT_CONTAINS(error, "expr:2: attempt to perform arithmetic on a nil value");
}

}  // namespace
}  // namespace swarmsim
