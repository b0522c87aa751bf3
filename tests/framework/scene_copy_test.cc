// Scene's copies and sizes (framework/scene_copy.cc): DuplicateSubtree
// copies a model's objects, rows, scripts and links with references
// remapped; ScaleSubtree and the per-object size factor.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "modules/proximity/proximity_sensor.h"

namespace swarmsim {
namespace {

// A tetrahedron, closed, counter-clockwise seen from outside.
std::shared_ptr<const TriangleMesh> Tetrahedron() {
  return std::make_shared<const TriangleMesh>(
      "tetra", std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
      std::vector<MeshTriangle>{{{0, 2, 1}}, {{0, 1, 3}}, {{0, 3, 2}}, {{1, 2, 3}}});
}

TEST(SceneTest, DuplicatingAModelCopiesObjectsScriptsAndRemapsReferences) {
  Scene scene;
  const ObjectId outside = scene.AddDummy("landmark", {}, {});
  ShapeData body_shape;
  body_shape.kind = ShapeKind::kCylinder;
  body_shape.dynamic = true;
  const ObjectId root = scene.AddShape("body", {}, {{1, 0, 0}, {}}, body_shape);
  const ObjectId motor = scene.AddJoint("motor", root, {{0, 0.1, 0}, {}}, JointData{});
  const ObjectId tip = scene.AddDummy("tip", motor, {});
  const ObjectId target = scene.AddDummy("target", root, {});
  const ObjectId beacon = scene.AddDummy("beacon", root, {});
  scene.LinkDummies(tip, target);      // internal reference
  scene.LinkDummies(beacon, outside);  // reference to outside the model
  auto source = std::make_shared<ScriptSource>(ScriptSource{"ctl.lua", "-- code"});
  scene.AttachScript(root, source);
  const int first = scene.MakeModelInstance(root, "bot", "bot#0");
  EXPECT_EQ(first, 0);

  const ObjectId copy = scene.DuplicateSubtree(root, {});
  ASSERT_EQ(scene.instances().size(), 2u);
  EXPECT_EQ(scene.instance_of(copy), 1);
  EXPECT_EQ(scene.instance(1).model_name, "bot");
  EXPECT_EQ(scene.instance(1).objects.size(), scene.instance(0).objects.size());
  // Objects copied, with their data.
  EXPECT_TRUE(scene.shape(copy).dynamic);
  const ObjectId copy_motor = scene.FindObject("./motor", copy);
  ASSERT_FALSE(copy_motor.IsNull());
  EXPECT_NE(copy_motor, motor);
  // Script copied, source shared (an asset, not a copy).
  ASSERT_NE(scene.script(copy), nullptr);
  EXPECT_EQ(scene.script(copy)->source.get(), source.get());
  // Internal link remapped to the copy; external link kept.
  const ObjectId copy_tip = scene.FindObject("./tip", copy);
  const ObjectId copy_target = scene.FindObject("./target", copy);
  EXPECT_EQ(scene.linked_dummy(copy_tip), copy_target);
  EXPECT_EQ(scene.linked_dummy(tip), target);
  EXPECT_EQ(scene.linked_dummy(scene.FindObject("./beacon", copy)), outside);
  // Every object of the copy belongs to the new instance.
  for (uint32_t s : scene.instance(1).objects) EXPECT_EQ(scene.instance_of_at(s), 1);

  // Deleting the copy deletes its objects and retires its instance.
  const size_t before = scene.object_count();
  scene.RemoveSubtree(copy);
  EXPECT_EQ(scene.object_count(), before - 5);
  EXPECT_FALSE(scene.instance(1).alive);
  EXPECT_FALSE(scene.IsValid(copy_tip));
  EXPECT_EQ(scene.linked_dummy(tip), target);
}

// A robot: a shape with a velocity, a turned joint carrying a dummy (its
// world pose goes through the joint), a proximity sensor (settings shared
// between copies), a script, a size factor; made a model instance.
struct Robot {
  Scene scene;
  ObjectId root;
  std::vector<std::pair<std::vector<uint32_t>, std::vector<uint32_t>>> heard;  // listener calls
  std::vector<size_t> objects_then;  // the scene's objects at each call

  Robot() {
    ShapeData body;
    body.kind = ShapeKind::kCylinder;
    body.dynamic = true;
    root = scene.AddShape("body", {}, {{1, 0, 0}, Quat::FromYaw(0.2)}, body);
    JointData motor;
    motor.position = 0.7;
    const ObjectId joint = scene.AddJoint("motor", root, {{0, 0.1, 0}, Quat::FromYaw(1)}, motor);
    scene.AddDummy("tip", joint, {{0.05, 0, 0.01}, {}});
    ShapeData wheel;
    wheel.kind = ShapeKind::kCylinder;
    scene.AddShape("wheel", joint, {{0, 0, -0.02}, {}}, wheel);
    ProximitySensorData sensor;
    sensor.settings.Edit().range = 0.1;
    sensor.distance = 0.04;
    proximity::AddSensor(&scene, "eye", root, {{0, 0.05, 0}, {}}, sensor);
    scene.AttachScript(root, std::make_shared<ScriptSource>(ScriptSource{"ctl.lua", "-- code"}));
    scene.ScaleSubtree(root, 1.5);
    scene.SetSimulatedState(scene.SlotOf(root), scene.world_pose(root), {0.5, 0, 0}, {0, 0, 2});
    scene.MakeModelInstance(root, "bot", "bot#0");
    scene.AddListener(&listener);
  }
  struct Listener : SceneListener {
    Robot* robot;
    explicit Listener(Robot* r) : robot(r) {}
    void OnSubtreeDuplicated(const Scene& scene, std::span<const uint32_t> sources,
                             std::span<const uint32_t> copies) override {
      robot->objects_then.push_back(scene.object_count());
      robot->heard.emplace_back(std::vector<uint32_t>(sources.begin(), sources.end()),
                                std::vector<uint32_t>(copies.begin(), copies.end()));
    }
    void OnSubtreeRemoved(const Scene&, std::span<const uint32_t>) override {}
  } listener{this};
};

uint64_t Structure(const Scene& scene) {
  StateHasher hasher;
  scene.AddStructure(&hasher);
  return hasher.Digest();
}

// Copies made together on two threads are the copies made one by one: the
// same slots, handles, names, rows, poses (bit for bit), scripts, size
// factors, robots and listener calls.
TEST(SceneTest, CopiesMadeTogetherAreTheCopiesMadeOneByOne) {
  Robot one, together;
  std::vector<Pose> poses;
  for (int i = 0; i < 300; ++i)
    poses.push_back({{0.3 * i, -0.1 * i, 0.02}, Quat::FromYaw(0.01 * i)});
  std::vector<ObjectId> roots_one;
  for (const Pose& X : poses) roots_one.push_back(one.scene.DuplicateSubtree(one.root, {}, &X));
  TaskScheduler scheduler(2);
  const std::vector<ObjectId> roots =
      together.scene.DuplicateSubtrees(together.root, poses, scheduler);
  EXPECT_EQ(roots, roots_one);
  const Scene& a = one.scene;
  const Scene& b = together.scene;
  ASSERT_EQ(b.slot_count(), a.slot_count());
  EXPECT_EQ(b.object_count(), a.object_count());
  EXPECT_EQ(Structure(b), Structure(a));
  for (uint32_t s = 0; s < a.slot_count(); ++s) {
    SCOPED_TRACE(s);
    ASSERT_EQ(b.IdAt(s), a.IdAt(s));
    EXPECT_EQ(b.name_at(s), a.name_at(s));
    EXPECT_EQ(b.parent(b.IdAt(s)), a.parent(a.IdAt(s)));
    EXPECT_EQ(b.children(b.IdAt(s)), a.children(a.IdAt(s)));
    EXPECT_EQ(b.type_at(s), a.type_at(s));
    EXPECT_EQ(b.instance_of_at(s), a.instance_of_at(s));
    EXPECT_EQ(b.size_factor_at(s), a.size_factor_at(s));
    const Pose& pa = a.world_pose_at(s);
    const Pose& pb = b.world_pose_at(s);
    EXPECT_EQ(std::memcmp(&pa, &pb, sizeof(Pose)), 0) << b.PathOf(b.IdAt(s));
    EXPECT_EQ(b.linear_velocity_at(s).x, a.linear_velocity_at(s).x);
    EXPECT_EQ(b.script_at(s) != nullptr, a.script_at(s) != nullptr);
    if (b.script_at(s)) {  // the source's script, shared (an asset)
      EXPECT_EQ(b.script_at(s)->source, b.script(together.root)->source);
    }
  }
  ASSERT_EQ(b.instances().size(), 301u);
  for (size_t i = 0; i < b.instances().size(); ++i) {
    EXPECT_EQ(b.instance(static_cast<int>(i)).name, a.instance(static_cast<int>(i)).name);
    EXPECT_EQ(b.instance(static_cast<int>(i)).objects, a.instance(static_cast<int>(i)).objects);
  }
  const ObjectId last = roots.back();
  EXPECT_EQ(b.instance(b.instance_of(last)).name, "bot#300");
  EXPECT_DOUBLE_EQ(b.joint(b.FindObject("./motor", last)).position, 0.7);
  EXPECT_DOUBLE_EQ(proximity::Sensor(b, b.FindObject("./eye", last)).distance, 0.04 * 1.5);
  EXPECT_TRUE(
      proximity::Sensor(b, b.FindObject("./eye", last))
          .settings.SameAs(proximity::Sensor(b, b.FindObject("./eye", together.root)).settings));
  EXPECT_EQ(together.heard, one.heard);
  ASSERT_EQ(together.heard.size(), 300u);
  // Made together indeed (not one by one, which the rest would not tell):
  // the listeners heard of the first copy once all were there.
  EXPECT_EQ(together.objects_then.front(), b.object_count());
  EXPECT_LT(one.objects_then.front(), a.object_count());
}

// A source the copies together do not handle (a dummy link remapped per
// copy) is copied one by one, with the same result.
TEST(SceneTest, CopiesTogetherOfALinkedModelAreMadeOneByOne) {
  Robot one, together;
  for (Robot* r : {&one, &together})
    r->scene.LinkDummies(r->scene.FindObject("./motor/tip", r->root),
                         r->scene.AddDummy("target", r->root, {}));
  const std::vector<Pose> poses(5, Pose{{2, 0, 0}, {}});
  for (const Pose& X : poses) one.scene.DuplicateSubtree(one.root, {}, &X);
  TaskScheduler scheduler(2);
  const std::vector<ObjectId> roots =
      together.scene.DuplicateSubtrees(together.root, poses, scheduler);
  EXPECT_EQ(Structure(together.scene), Structure(one.scene));
  const Scene& b = together.scene;
  EXPECT_EQ(b.linked_dummy(b.FindObject("./motor/tip", roots[4])),
            b.FindObject("./target", roots[4]));
  EXPECT_EQ(together.objects_then, one.objects_then);  // one by one: told as each was made
}

// Velocities are kept for shapes only (the bodies backends simulate), and a
// slot's rare values (custom data, size factor, dummy link) only where set:
// a copy takes them, a removed object's slot comes back without them.
// A copy placed as it is made is where placing it afterwards puts it, its
// objects' names shared with the source's (and kept when the source goes).
TEST(SceneTest, ACopyPlacedAsItIsMadeMatchesOnePlacedAfter) {
  Scene scene;
  const ObjectId root = scene.AddDummy("body", {}, {{1, 0, 0}, Quat::FromYaw(0.3)});
  const ObjectId arm = scene.AddDummy("arm", root, {{0, 0.1, 0.2}, Quat::FromYaw(-1)});
  scene.AddDummy("hand", arm, {{0.05, 0, 0}, {}});
  scene.MakeModelInstance(root, "bot", "bot#0");
  const Pose X{{4, -2, 0.5}, Quat::FromYaw(2)};
  const ObjectId placed_after = scene.DuplicateSubtree(root, {});
  scene.SetWorldPose(placed_after, X);
  const ObjectId placed_now = scene.DuplicateSubtree(root, {}, &X);
  for (const char* path : {".", "./arm", "./arm/hand"}) {
    const Pose a = scene.world_pose(path[1] ? scene.FindObject(path, placed_after) : placed_after);
    const Pose b = scene.world_pose(path[1] ? scene.FindObject(path, placed_now) : placed_now);
    EXPECT_EQ(a.p.x, b.p.x) << path;
    EXPECT_EQ(a.p.y, b.p.y) << path;
    EXPECT_EQ(a.p.z, b.p.z) << path;
    EXPECT_EQ(a.q.w, b.q.w) << path;
    EXPECT_EQ(a.q.z, b.q.z) << path;
  }
  EXPECT_NEAR(scene.world_pose(placed_now).p.x, 4, 1e-15);
  // The source unchanged; names shared, and still there once the source is removed.
  EXPECT_NEAR(scene.world_pose(root).p.x, 1, 1e-15);
  EXPECT_EQ(scene.name(scene.FindObject("./arm/hand", placed_now)), "hand");
  scene.RemoveSubtree(root);
  scene.RemoveSubtree(placed_after);
  EXPECT_EQ(scene.name(scene.FindObject("./arm/hand", placed_now)), "hand");
  EXPECT_EQ(scene.name(scene.FindObject("./arm", placed_now)), "arm");
}

TEST(SceneTest, VelocitiesAndRareValuesFollowCopiesAndRemovals) {
  Scene scene;
  ShapeData body_shape;
  body_shape.dynamic = true;
  const ObjectId body = scene.AddShape("body", {}, {}, body_shape);
  const ObjectId marker = scene.AddDummy("marker", body, {{0.1, 0, 0}, {}});
  const ObjectId target = scene.AddDummy("target", body, {{0.2, 0, 0}, {}});
  scene.MakeModelInstance(body, "bot", "bot#0");
  scene.SetSimulatedState(scene.SlotOf(body), scene.world_pose(body), {0.5, 0, 0}, {0, 0, 2});
  scene.SetSimulatedState(scene.SlotOf(marker), scene.world_pose(marker), {9, 9, 9}, {9, 9, 9});
  EXPECT_EQ(scene.linear_velocity_at(scene.SlotOf(body)).x, 0.5);
  EXPECT_EQ(scene.angular_velocity_at(scene.SlotOf(body)).z, 2);
  // A dummy is never simulated with a velocity: it reads zero.
  EXPECT_EQ(scene.linear_velocity_at(scene.SlotOf(marker)).x, 0);
  scene.LinkDummies(marker, target);
  scene.WriteCustomData(marker, "tag", "value", nullptr);
  scene.ScaleSubtree(body, 2);

  const ObjectId copy = scene.DuplicateSubtree(body, {});
  const ObjectId copy_marker = scene.FindObject("./marker", copy);
  const ObjectId copy_target = scene.FindObject("./target", copy);
  ASSERT_FALSE(copy_marker.IsNull());
  EXPECT_EQ(scene.linear_velocity_at(scene.SlotOf(copy)).x, 0.5);
  EXPECT_EQ(scene.size_factor(copy_marker), 2);
  ASSERT_NE(scene.ReadCustomData(copy_marker, "tag"), nullptr);
  EXPECT_EQ(*scene.ReadCustomData(copy_marker, "tag"), "value");
  EXPECT_EQ(scene.linked_dummy(copy_marker), copy_target);  // remapped inside the copy
  EXPECT_EQ(scene.linked_dummy(marker), target);

  // Removing the target unlinks the marker; new objects in the freed slots
  // start clean.
  scene.RemoveSubtree(target);
  EXPECT_TRUE(scene.linked_dummy(marker).IsNull());
  scene.RemoveSubtree(copy);
  const ObjectId fresh_shape = scene.AddShape("fresh", {}, {}, body_shape);
  const ObjectId fresh_dummy = scene.AddDummy("fresh_dummy", {}, {});
  for (const ObjectId fresh : {fresh_shape, fresh_dummy}) {
    EXPECT_EQ(scene.linear_velocity_at(scene.SlotOf(fresh)).x, 0);
    EXPECT_EQ(scene.angular_velocity_at(scene.SlotOf(fresh)).z, 0);
    EXPECT_EQ(scene.size_factor(fresh), 1);
    EXPECT_EQ(scene.ReadCustomData(fresh, "tag"), nullptr);
  }
  EXPECT_TRUE(scene.linked_dummy(fresh_dummy).IsNull());
  EXPECT_EQ(scene.linear_velocity_at(scene.SlotOf(body)).x, 0.5);  // the original keeps its own
}

TEST(SceneScaleTest, ScalesGeometryJointsSensorsAndMasses) {
  Scene scene;
  ShapeData body;
  body.kind = ShapeKind::kBox;
  body.size = {0.2, 0.1, 0.05};
  body.mass = 2;
  const ObjectId root = scene.AddShape("root", {}, {{5, 0, 1}, {}}, body);
  JointData slider;
  slider.settings.Edit().type = JointType::kPrismatic;
  slider.position = 0.1;
  slider.settings.Edit().min_position = -0.2;
  slider.settings.Edit().max_position = 0.3;
  slider.settings.Edit().max_force = 4;
  const ObjectId prismatic = scene.AddJoint("slider", root, {{0, 0, 0.1}, {}}, slider);
  JointData hinge;
  hinge.position = 0.5;
  hinge.settings.Edit().max_force = 3;
  const ObjectId revolute = scene.AddJoint("hinge", root, {{0.1, 0, 0}, {}}, hinge);
  ShapeData mesh;
  mesh.kind = ShapeKind::kMesh;
  mesh.mesh = Tetrahedron();
  mesh.size = mesh.mesh->CenteredExtents();
  const ObjectId m1 = scene.AddShape("m1", prismatic, {}, mesh);
  const ObjectId m2 = scene.AddShape("m2", revolute, {}, mesh);
  ProximitySensorData sensor;
  sensor.settings.Edit().range = 0.1;
  const ObjectId eye = proximity::AddSensor(&scene, "eye", root, {{0, 0.05, 0}, {}}, sensor);
  const uint64_t version = scene.structure_version();

  scene.ScaleSubtree(root, 2);
  EXPECT_GT(scene.structure_version(), version);
  // The root stays where it is; everything below scales about it.
  EXPECT_DOUBLE_EQ(scene.world_pose(root).p.x, 5);
  EXPECT_DOUBLE_EQ(scene.shape(root).size.x, 0.4);
  EXPECT_DOUBLE_EQ(scene.shape(root).mass, 16);
  EXPECT_DOUBLE_EQ(scene.local_pose(prismatic).p.z, 0.2);
  EXPECT_DOUBLE_EQ(scene.joint(prismatic).position, 0.2);
  EXPECT_DOUBLE_EQ(scene.joint(prismatic).settings->min_position, -0.4);
  EXPECT_DOUBLE_EQ(scene.joint(prismatic).settings->max_position, 0.6);
  EXPECT_DOUBLE_EQ(scene.joint(prismatic).settings->max_force, 32);  // N: x s^3
  EXPECT_DOUBLE_EQ(scene.joint(revolute).position, 0.5);             // angles unchanged
  EXPECT_DOUBLE_EQ(scene.joint(revolute).settings->max_force, 48);   // N m: x s^4
  EXPECT_DOUBLE_EQ(scene.world_pose(m1).p.z, 1 + 0.2 + 0.2);         // offset + slider
  EXPECT_DOUBLE_EQ(proximity::Sensor(scene, eye).range(), 0.2);
  // One scaled asset for both shapes that shared the original.
  EXPECT_EQ(scene.shape(m1).mesh, scene.shape(m2).mesh);
  EXPECT_NE(scene.shape(m1).mesh, mesh.mesh);
  EXPECT_DOUBLE_EQ(scene.shape(m1).mesh->hi().x, 2);
  EXPECT_DOUBLE_EQ(mesh.mesh->hi().x, 1);  // the original is untouched
  EXPECT_DOUBLE_EQ(scene.shape(m1).size.x, 4);
  for (ObjectId id : {root, prismatic, m1, eye}) EXPECT_DOUBLE_EQ(scene.size_factor(id), 2);

  // Factors accumulate; a part can be scaled on its own.
  scene.ScaleSubtree(prismatic, 0.5);
  EXPECT_DOUBLE_EQ(scene.size_factor(root), 2);
  EXPECT_DOUBLE_EQ(scene.size_factor(m1), 1);
  EXPECT_DOUBLE_EQ(scene.shape(m1).mesh->hi().x, 1);
}

TEST(SceneScaleTest, DuplicatesKeepTheSizeFactor) {
  Scene scene;
  const ObjectId root = scene.AddShape("bot", {}, {}, ShapeData{});
  const ObjectId child = scene.AddDummy("tip", root, {{0.1, 0, 0}, {}});
  scene.MakeModelInstance(root, "bot", "bot#0");
  EXPECT_DOUBLE_EQ(scene.size_factor(root), 1);
  scene.ScaleSubtree(root, 1.5);
  const ObjectId copy = scene.DuplicateSubtree(root, {});
  EXPECT_DOUBLE_EQ(scene.size_factor(copy), 1.5);
  const ObjectId copy_tip = scene.children(copy).at(0);
  EXPECT_DOUBLE_EQ(scene.size_factor(copy_tip), 1.5);
  EXPECT_NEAR(scene.local_pose(copy_tip).p.x, 0.15, 1e-15);
  EXPECT_DOUBLE_EQ(scene.shape(copy).size.x, 0.15);
  // A freed slot that is reused starts at 1 again.
  scene.RemoveSubtree(child);
  EXPECT_DOUBLE_EQ(scene.size_factor(scene.AddDummy("new", {}, {})), 1);
}

TEST(SceneScaleTest, BadFactorsAreRefused) {
  Scene scene;
  const ObjectId root = scene.AddDummy("d", {}, {});
  for (double bad : {0.0, -1.0, double(NAN), double(INFINITY)}) {
    try {
      scene.ScaleSubtree(root, bad);
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("finite number above 0"), std::string::npos);
    }
  }
  EXPECT_DOUBLE_EQ(scene.size_factor(root), 1);
}

}  // namespace
}  // namespace swarmsim
