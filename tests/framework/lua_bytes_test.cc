// framework/lua_bytes.h: the bytes a script hands a device. A table with a
// hole or another key is refused, naming the key ({1, 2, nil, 4} sent
// 1,2 and {x = 1} sent nothing, without a word).
#include "framework/lua_bytes.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"  // lua.hpp

namespace swarmsim {
namespace {

class LuaBytesTest : public ::testing::Test {
 protected:
  LuaBytesTest() : L(luaL_newstate()) {}
  ~LuaBytesTest() override { lua_close(L); }

  // ArgBytes of the value `expression` evaluates to, at most `max` bytes;
  // *error gets the message of a refusal.
  std::vector<uint8_t> Bytes(const std::string& expression, size_t max, std::string* error) {
    error->clear();
    lua_settop(L, 0);
    EXPECT_EQ(luaL_dostring(L, ("return " + expression).c_str()), LUA_OK);
    try {
      return ArgBytes(L, 1, max, "data", [](size_t n) { return std::to_string(n) + " bytes"; });
    } catch (const Error& e) {
      *error = e.what();
      return {};
    }
  }

  lua_State* L;
};

TEST_F(LuaBytesTest, StringsAndSequencesAreTheirBytes) {
  std::string error;
  EXPECT_EQ(Bytes("'AB\\0'", 4, &error), (std::vector<uint8_t>{65, 66, 0}));
  EXPECT_EQ(error, "");
  EXPECT_EQ(Bytes("{7, 0, 255, 1}", 4, &error), (std::vector<uint8_t>{7, 0, 255, 1}));
  EXPECT_EQ(error, "");
  EXPECT_EQ(Bytes("{}", 4, &error), std::vector<uint8_t>{});
  EXPECT_EQ(error, "");
  EXPECT_EQ(Bytes("{3.0}", 4, &error), std::vector<uint8_t>{3});  // a whole float is a byte
  EXPECT_EQ(error, "");
}

TEST_F(LuaBytesTest, AHoleOrAnotherKeyIsRefusedNamingTheKey) {
  std::string error;
  Bytes("{1, 2, nil, 4}", 8, &error);
  EXPECT_EQ(error,
            "the data table has key [4] besides its bytes t[1]..t[2]: a table of bytes is a "
            "sequence with no hole (nil is no byte: write 0) and no other keys");
  Bytes("{x = 1}", 8, &error);
  EXPECT_NE(error.find("the data table has key 'x' but no t[1]"), std::string::npos) << error;
  Bytes("{[0] = 5, 6}", 8, &error);
  EXPECT_NE(error.find("key [0] besides its bytes t[1]..t[1]"), std::string::npos) << error;
  Bytes("{1, [true] = 2}", 8, &error);
  EXPECT_NE(error.find("key a boolean"), std::string::npos) << error;
  Bytes("{1, [1.5] = 2}", 8, &error);
  EXPECT_NE(error.find("the data table has key"), std::string::npos) << error;
}

TEST_F(LuaBytesTest, BadElementsTooManyBytesAndOtherTypesAreRefused) {
  std::string error;
  Bytes("{1, 256}", 8, &error);
  EXPECT_EQ(error, "element 2 of the data must be an integer from 0 to 255 (a byte)");
  Bytes("{1.5}", 8, &error);
  EXPECT_NE(error.find("element 1"), std::string::npos) << error;
  Bytes("'hello'", 4, &error);
  EXPECT_EQ(error, "5 bytes");
  Bytes("{1, 2, 3, 4, 5, 6}", 4, &error);
  EXPECT_EQ(error, "6 bytes");
  Bytes("12", 4, &error);
  EXPECT_EQ(error,
            "bad argument #1 (a string of bytes or a table of integers 0..255 expected, "
            "got number)");
}

}  // namespace
}  // namespace swarmsim
