#include "framework/name_pool.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace swarmsim {
namespace {

TEST(NamePoolTest, OneStringPerDistinctName) {
  NamePool pool;
  const uint32_t a = pool.Intern("leftMotor");
  const uint32_t b = pool.Intern("prox");
  EXPECT_NE(a, b);
  for (int copy = 0; copy < 1000; ++copy) EXPECT_EQ(pool.Intern("prox"), b);
  EXPECT_EQ(pool.size(), 2u);
  EXPECT_EQ(pool[a], "leftMotor");
  EXPECT_EQ(pool[b], "prox");
}

TEST(NamePoolTest, ANameGoesWithItsLastReference) {
  NamePool pool;
  const uint32_t a = pool.Intern("wheel");
  pool.Retain(a);  // a copy of the object
  pool.Release(a);
  EXPECT_EQ(pool[a], "wheel");  // the copy still has it
  EXPECT_EQ(pool.size(), 1u);
  pool.Release(a);
  EXPECT_EQ(pool.size(), 0u);
  // Its id is reused for the next new name, which reads right.
  const uint32_t b = pool.Intern("footbot#7");
  EXPECT_EQ(b, a);
  EXPECT_EQ(pool[b], "footbot#7");
  EXPECT_EQ(pool.Intern("footbot#7"), b);
}

TEST(NamePoolTest, NamesStayPutWhileOthersArrive) {
  NamePool pool;
  const uint32_t first = pool.Intern("first");
  const std::string* where = &pool[first];
  std::vector<uint32_t> ids;
  for (int i = 0; i < 10000; ++i) ids.push_back(pool.Intern("robot#" + std::to_string(i)));
  EXPECT_EQ(&pool[first], where);  // references handed out stay valid
  EXPECT_EQ(*where, "first");
  for (int i = 0; i < 10000; i += 997) EXPECT_EQ(pool[ids[i]], "robot#" + std::to_string(i));
  // Releasing and re-interning keeps lookups right.
  for (int i = 0; i < 10000; i += 2) pool.Release(ids[i]);
  EXPECT_EQ(pool.size(), 5001u);
  EXPECT_EQ(pool.Intern("robot#1"), ids[1]);
  const uint32_t again = pool.Intern("robot#0");
  EXPECT_EQ(pool[again], "robot#0");
}

}  // namespace
}  // namespace swarmsim
