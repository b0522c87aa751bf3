#include "framework/scene.h"

#include <gtest/gtest.h>

#include "framework/error.h"

namespace swarmsim {
namespace {

TEST(SceneTest, StaleHandleIsRejected) {
  Scene scene;
  const ObjectId a = scene.AddDummy("a", {}, {});
  ASSERT_TRUE(scene.IsValid(a));
  scene.RemoveSubtree(a);
  EXPECT_FALSE(scene.IsValid(a));
  EXPECT_THROW(scene.world_pose(a), Error);
  // The slot is reused by the next object with a new generation.
  const ObjectId b = scene.AddDummy("b", {}, {});
  EXPECT_EQ(b.index1, a.index1);
  EXPECT_NE(b.generation, a.generation);
  EXPECT_FALSE(scene.IsValid(a));
  EXPECT_TRUE(scene.IsValid(b));
}

}  // namespace
}  // namespace swarmsim
