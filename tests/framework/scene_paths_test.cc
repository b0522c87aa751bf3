// framework/scene_paths.cc: object paths, found from where the caller stands.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"

namespace swarmsim {
namespace {

TEST(ScenePathsTest, PathsResolveRelativeToTheCaller) {
  Scene scene;
  const ObjectId robot = scene.AddDummy("robot", {}, {});
  const ObjectId body = scene.AddDummy("body", robot, {});
  const ObjectId s0 = scene.AddDummy("sensor", body, {});
  const ObjectId s1 = scene.AddDummy("sensor", body, {});
  scene.MakeModelInstance(robot, "bot", "bot#0");
  EXPECT_EQ(scene.FindObject("/robot/body"), body);
  EXPECT_EQ(scene.FindObject("./sensor", body), s0);
  EXPECT_EQ(scene.FindObject("./sensor[1]", body), s1);
  EXPECT_EQ(scene.FindObject(":/sensor[1]", s0), s1);
  EXPECT_EQ(scene.FindObject(".", body), body);
  EXPECT_TRUE(scene.FindObject("./sensor[2]", body).IsNull());
  EXPECT_TRUE(scene.FindObject("/nothing").IsNull());
  EXPECT_THROW(scene.FindObject("./sensor[x]", body), Error);
  EXPECT_THROW(scene.FindObject("sensor", body), Error);
  EXPECT_THROW(scene.FindObject("./nothing[x]", body), Error) << "malformed, whatever the name";
  EXPECT_EQ(scene.PathOf(s1), "/robot/body/sensor");
  // Renamed and removed objects: found by their names now only.
  scene.set_name(s1, "eye");
  EXPECT_TRUE(scene.FindObject("./sensor[1]", body).IsNull());
  EXPECT_EQ(scene.FindObject("./eye", body), s1);
  scene.RemoveSubtree(s0);
  EXPECT_TRUE(scene.FindObject("./sensor", body).IsNull());
  EXPECT_EQ(scene.FindObject("/robot/body/eye"), s1);
  const ObjectId s2 = scene.AddDummy("sensor", s1, {});  // the name back, elsewhere
  EXPECT_EQ(scene.FindObject("./sensor", body), s2);
  EXPECT_EQ(scene.FindObject("./eye/sensor", body), s2);
}

// Lookups by path remember the names they met (a swarm looks up the same
// few a million times): two scenes whose pools number the same name
// differently, and a name whose number went to another name, still find
// what each scene holds now.
TEST(ScenePathsTest, PathLookupsAnswerForEachSceneAsItIsNow) {
  Scene a, b;
  const ObjectId a_robot = a.AddDummy("robot", {}, {});
  const ObjectId a_eye = a.AddDummy("eye", a_robot, {});
  const ObjectId b_robot = b.AddDummy("robot", {}, {});
  b.AddDummy("wheel", b_robot, {});  // "eye" gets another number in b's pool
  const ObjectId b_eye = b.AddDummy("eye", b_robot, {});
  for (int round = 0; round < 3; ++round) {
    EXPECT_EQ(a.FindObject("./eye", a_robot), a_eye);
    EXPECT_EQ(b.FindObject("./eye", b_robot), b_eye);
    EXPECT_TRUE(a.FindObject("./wheel", a_robot).IsNull());
  }
  // "eye" leaves a's pool and its number goes to a new name.
  a.RemoveSubtree(a_eye);
  const ObjectId a_arm = a.AddDummy("arm", a_robot, {});
  EXPECT_TRUE(a.FindObject("./eye", a_robot).IsNull());
  EXPECT_EQ(a.FindObject("./arm", a_robot), a_arm);
  EXPECT_EQ(b.FindObject("./eye", b_robot), b_eye);
  // Renamed: found by its new name only.
  b.set_name(b_eye, "arm");
  EXPECT_TRUE(b.FindObject("./eye", b_robot).IsNull());
  EXPECT_EQ(b.FindObject("./arm", b_robot), b_eye);
}

// A robot looks up ./sensor[0], ./sensor[1], ... in turn, and each lookup
// resumes where the thread's last one stopped: only in the same scene,
// unchanged since.
TEST(ScenePathsTest, PathLookupsInTurnSeeTheSceneAsItIsNow) {
  Scene scene;
  const ObjectId robot = scene.AddDummy("robot", {}, {});
  std::vector<ObjectId> sensors;
  for (int i = 0; i < 4; ++i) sensors.push_back(scene.AddDummy("sensor", robot, {}));
  const auto find = [&](int i) {
    return scene.FindObject("./sensor[" + std::to_string(i) + "]", robot);
  };
  for (int i = 0; i < 4; ++i) EXPECT_EQ(find(i), sensors[i]);
  EXPECT_TRUE(find(4).IsNull());
  for (int i = 3; i >= 0; --i) EXPECT_EQ(find(i), sensors[i]);  // backwards: from the start
  // A sensor added under the first one comes second in hierarchy order.
  EXPECT_EQ(find(1), sensors[1]);
  const ObjectId inner = scene.AddDummy("sensor", sensors[0], {});
  EXPECT_EQ(find(2), sensors[1]);
  EXPECT_EQ(find(1), inner);
  // The first one renamed: the others move up.
  EXPECT_EQ(find(2), sensors[1]);
  scene.set_name(sensors[0], "eye");
  EXPECT_EQ(find(3), sensors[3]);
  EXPECT_TRUE(find(4).IsNull());
}

// Two scenes with the same slots, names and number of changes, whose
// sensors come in different orders: a lookup in one does not resume a walk
// made in the other.
TEST(ScenePathsTest, PathLookupsInTurnDoNotCrossScenes) {
  Scene a, b;
  const ObjectId a_robot = a.AddDummy("robot", {}, {});
  a.AddDummy("x", a_robot, {});
  a.AddDummy("y", a_robot, {});
  const ObjectId a_first = a.AddDummy("sensor", a_robot, {});
  const ObjectId a_second = a.AddDummy("sensor", a_robot, {});
  const ObjectId b_robot = b.AddDummy("robot", {}, {});
  b.AddDummy("x", b_robot, {});
  const ObjectId b_y = b.AddDummy("y", b_robot, {});
  const ObjectId b_second = b.AddDummy("sensor", b_robot, {});  // slot 3, after y's subtree
  const ObjectId b_first = b.AddDummy("sensor", b_y, {});       // slot 4, under y
  ASSERT_EQ(a_first.index(), b_second.index());
  EXPECT_EQ(a.FindObject("./sensor[0]", a_robot), a_first);
  EXPECT_EQ(b.FindObject("./sensor[1]", b_robot), b_second);
  EXPECT_EQ(a.FindObject("./sensor[1]", a_robot), a_second);
  EXPECT_EQ(b.FindObject("./sensor[0]", b_robot), b_first);
}

// Matches count in hierarchy order (depth first, children in the order they
// were added), and a search never leaves the subtree it starts from.
TEST(ScenePathsTest, PathIndicesCountInHierarchyOrderWithinTheSubtree) {
  Scene scene;
  const ObjectId robot = scene.AddDummy("robot", {}, {});
  const ObjectId a = scene.AddDummy("a", robot, {});
  const ObjectId x = scene.AddDummy("sensor", a, {});
  const ObjectId b = scene.AddDummy("sensor", robot, {});
  const ObjectId y = scene.AddDummy("sensor", b, {});
  const ObjectId leaf = scene.AddDummy("leaf", robot, {});
  const ObjectId z = scene.AddDummy("sensor", robot, {});
  EXPECT_EQ(scene.FindObject("./sensor", robot), x);
  EXPECT_EQ(scene.FindObject("./sensor[1]", robot), b);
  EXPECT_EQ(scene.FindObject("./sensor[2]", robot), y);
  EXPECT_EQ(scene.FindObject("./sensor[3]", robot), z);
  EXPECT_TRUE(scene.FindObject("./sensor[4]", robot).IsNull());
  // Each element takes its match and searches below it, no backtracking.
  EXPECT_TRUE(scene.FindObject("./sensor/sensor", robot).IsNull());  // below x: nothing
  EXPECT_EQ(scene.FindObject("./sensor[1]/sensor", robot), y);
  EXPECT_EQ(scene.FindObject("./a/sensor", robot), x);
  EXPECT_TRUE(scene.FindObject("./sensor[1]", a).IsNull());  // not b: a's subtree only
  EXPECT_TRUE(scene.FindObject("./sensor", leaf).IsNull());  // not z, its next sibling
  EXPECT_EQ(scene.FindObject("./sensor", b), y);
}

}  // namespace
}  // namespace swarmsim
