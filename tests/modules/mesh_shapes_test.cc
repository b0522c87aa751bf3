// Mesh shapes in the modules: proximity rays against static and robot
// meshes (exact, equal to the box they model), ODE trimesh contacts, the
// Box2D hull as a wall, and copies sharing one asset.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/dynamics/box2d/box2d_backend.h"
#include "modules/proximity/proximity.h"

namespace swarmsim {
namespace {

// A closed box mesh of full extents `size`, centred on the frame, wound outwards.
std::shared_ptr<const TriangleMesh> BoxMesh(const Vec3& size) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i)
    v.push_back({(i & 1 ? 0.5 : -0.5) * size.x, (i & 2 ? 0.5 : -0.5) * size.y,
                 (i & 4 ? 0.5 : -0.5) * size.z});
  const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  std::vector<MeshTriangle> t;
  for (const auto& q : quads) {
    t.push_back({{q[0], q[1], q[2]}});
    t.push_back({{q[0], q[2], q[3]}});
  }
  return std::make_shared<const TriangleMesh>("box", v, t);
}

ShapeData Mesh(const std::shared_ptr<const TriangleMesh>& mesh, bool dynamic = false,
               double mass = 1) {
  ShapeData s;
  s.kind = ShapeKind::kMesh;
  s.mesh = mesh;
  s.size = mesh->CenteredExtents();
  s.dynamic = dynamic;
  s.mass = mass;
  return s;
}
ShapeData Box(const Vec3& size, bool dynamic = false, double mass = 1) {
  ShapeData s;
  s.kind = ShapeKind::kBox;
  s.size = size;
  s.dynamic = dynamic;
  s.mass = mass;
  return s;
}

// --- Proximity --------------------------------------------------------------------------

// Sensor readings for rays at `poses` against one shape (static or a robot's).
std::vector<ProximitySensorData> Readings(const ShapeData& shape, const Pose& X_WS, bool robot,
                                          const std::vector<Pose>& poses) {
  Scene scene;
  if (robot) {
    const ObjectId root = scene.AddDummy("target", {}, X_WS);
    scene.AddShape("body", root, {}, shape);
    scene.MakeModelInstance(root, "target", "target#0");
  } else {
    scene.AddShape("wall", {}, X_WS, shape);
  }
  std::vector<ObjectId> sensors;
  for (const Pose& X_WR : poses) {
    ProximitySensorData ray;
    ray.settings.Edit().range = 1.5;
    sensors.push_back(proximity::AddSensor(&scene, "s", {}, X_WR, ray));
  }
  scene.UpdateWorldPoses();
  auto backend = proximity::MakeBackend();
  ProximitySettings settings;
  settings.octree_resolution = 0.05;
  backend->Build(scene, settings);
  backend->Update(scene);
  for (size_t i = 0; i < scene.instances().size(); ++i)
    backend->SenseInstance(&scene, static_cast<int>(i));
  backend->SenseSceneSensors(&scene);
  std::vector<ProximitySensorData> out;
  for (ObjectId s : sensors) out.push_back(proximity::Sensor(scene, s));
  return out;
}

class MeshProximity : public ::testing::TestWithParam<bool> {};

TEST_P(MeshProximity, DistanceToAMeshCubeEqualsTheBoxDistance) {
  const bool robot = GetParam();
  const Vec3 size{0.3, 0.4, 0.5};
  const Pose X_WS{{1.0, 0.2, 0.25}, Quat::FromRollPitchYaw(0.1, -0.2, 0.7)};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Pose> poses;
  for (int i = 0; i < 300; ++i) {
    // Rays from around the box, aimed near its centre (many hit, some miss).
    const Vec3 p = X_WS.p + Vec3{u(rng), u(rng), u(rng)} * 0.9;
    const Vec3 aim = X_WS.p + Vec3{u(rng), u(rng), u(rng)} * 0.3;
    const Vec3 z = (aim - p).Normalized();
    // Orientation taking +z onto `z`.
    const Vec3 axis = Vec3{0, 0, 1}.Cross(z);
    const double angle = std::atan2(axis.Norm(), z.z);
    poses.push_back({p, axis.Norm() > 0 ? Quat::FromAxisAngle(axis, angle) : Quat{}});
  }
  const auto box = Readings(Box(size), X_WS, robot, poses);
  const auto mesh = Readings(Mesh(BoxMesh(size)), X_WS, robot, poses);
  int hits = 0;
  for (size_t i = 0; i < poses.size(); ++i) {
    ASSERT_EQ(mesh[i].detected, box[i].detected) << i;
    EXPECT_NEAR(mesh[i].distance, box[i].distance, 1e-9) << i;
    hits += box[i].detected;
  }
  EXPECT_GT(hits, 100);
}

TEST_P(MeshProximity, RayBesideTheMeshMisses) {
  const bool robot = GetParam();
  // A 0.2 m mesh cube at the origin; rays along +x passing 1 mm beside it.
  const Quat along_x = Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
  const std::vector<Pose> poses = {
      {{-0.5, 0.101, 0}, along_x}, {{-0.5, 0, 0.101}, along_x}, {{-0.5, 0, 0.099}, along_x}};
  const auto r = Readings(Mesh(BoxMesh({0.2, 0.2, 0.2})), {{0, 0, 0}, {}}, robot, poses);
  EXPECT_FALSE(r[0].detected);
  EXPECT_FALSE(r[1].detected);
  ASSERT_TRUE(r[2].detected);
  EXPECT_NEAR(r[2].distance, 0.4, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(StaticAndRobot, MeshProximity, ::testing::Bool(),
                         [](const auto& info) { return info.param ? "Robot" : "Static"; });

// --- ODE ------------------------------------------------------------------------------------

TEST(MeshOde, MeshBoxRestsOnTheGroundAtItsHalfHeight) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  WorldSettings s;
  s.physics = "ode";
  s.time_step = 0.01;
  World world(s, registry);
  world.set_log_sink([](std::string_view) {});
  const ObjectId crate =
      world.scene().AddShape("crate", {}, {{0, 0, 0.4}, {}}, Mesh(BoxMesh({0.3, 0.2, 0.1}), true));
  world.Start();
  for (int i = 0; i < 300; ++i) world.Step();  // 3 s: falls, settles
  const Pose X = world.scene().world_pose(crate);
  EXPECT_NEAR(X.p.z, 0.05, 2e-3);
  EXPECT_NEAR(X.p.x, 0, 1e-3);
  EXPECT_NEAR(X.p.y, 0, 1e-3);
  EXPECT_NEAR(std::abs(X.q.w), 1, 1e-4);  // still flat
}

// --- Box2D ------------------------------------------------------------------------------------

TEST(MeshBox2d, RobotStopsAtAMeshWall) {
  for (const bool mesh_wall : {false, true}) {
    Scene scene;
    // Wall: a 0.1 x 2 x 0.2 box (or mesh) whose near face is at x = 1.
    const Vec3 wall_size{0.1, 2, 0.2};
    scene.AddShape("wall", {}, {{1.05, 0, 0.1}, {}},
                   mesh_wall ? Mesh(BoxMesh(wall_size)) : Box(wall_size));
    // A dynamic 0.1 m cube sliding at it at 0.5 m/s (no gravity: no floor friction).
    ShapeData cube = Box({0.1, 0.1, 0.1}, true);
    const ObjectId body = scene.AddShape("cube", {}, {{0.5, 0, 0.05}, {}}, cube);
    scene.MakeModelInstance(body, "cube", "cube#0");
    scene.SetSimulatedState(scene.SlotOf(body), scene.world_pose(body), {0.5, 0, 0}, {});
    scene.UpdateWorldPoses();
    auto backend = box2d::MakeBackend({});
    DynamicsSettings settings;
    settings.gravity = 0;
    backend->Build(scene, settings);
    double max_x = -1;
    for (int i = 0; i < 30; ++i) {
      backend->Step(&scene, 0.01, 10);
      scene.UpdateWorldPoses();
      max_x = std::max(max_x, scene.world_pose(body).p.x);
    }
    // The cube's front face (x + 0.05) stops at the wall's face (x = 1).
    EXPECT_NEAR(max_x + 0.05, 1.0, 3e-3) << (mesh_wall ? "mesh" : "box");
  }
}

// --- Sharing ----------------------------------------------------------------------------------

TEST(MeshAsset, CopiesOfAModelShareOneAsset) {
  Scene scene;
  const auto mesh = BoxMesh({0.1, 0.1, 0.1});
  const ObjectId root = scene.AddDummy("bot", {}, {});
  const ObjectId body = scene.AddShape("body", root, {}, Mesh(mesh));
  scene.MakeModelInstance(root, "bot", "bot#0");
  scene.ReserveForCopies(root, 100);
  for (int i = 0; i < 100; ++i) scene.DuplicateSubtree(root, {});
  EXPECT_EQ(scene.instances().size(), 101u);
  for (const ShapeData& s : scene.shapes()) {
    EXPECT_EQ(s.mesh.get(), mesh.get());
    EXPECT_EQ(&s, &scene.shape(body));  // one ShapeData for every copy (settings)
  }
  EXPECT_EQ(mesh.use_count(), 1 + 1);  // this test's pointer and the shared settings'
  // A copy given its own colour gets its own settings, with the same asset.
  const ObjectId seventh = scene.FindObject("./body", scene.instance(7).root);
  const double before = scene.shape(body).color.x;
  scene.mutable_shape(seventh).color = {1 - before, 0, 0};
  EXPECT_EQ(mesh.use_count(), 1 + 2);
  EXPECT_EQ(scene.shape(seventh).mesh.get(), mesh.get());
  EXPECT_EQ(scene.shape(seventh).color.x, 1 - before);
  EXPECT_EQ(scene.shape(scene.FindObject("./body", scene.instance(8).root)).color.x, before);
  EXPECT_EQ(scene.shape(body).color.x, before);
  EXPECT_EQ(scene.shape(body).mesh->vertices().size(), 8u);
}

}  // namespace
}  // namespace swarmsim
