// Mesh shapes in world and model files: STL/OBJ read once per file and
// shared by every copy, scale, and the mistakes a user would make.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

const fs::path kMeshes = fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/meshes";

class LoaderMeshTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RegisterBuiltinModules(&registry_);
    dir_ = fs::temp_directory_path() /
           ("swarmsim_loader_mesh_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "models");
    fs::copy_file(kMeshes / "unit_cube.stl", dir_ / "models/cube.stl");
    fs::copy_file(kMeshes / "tetrahedron.stl", dir_ / "tetra.stl");
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  // A world with `count` copies of models/bot.yaml, whose body shape has `shape_keys`.
  LoadedWorld Load(const std::string& shape_keys, int count = 1,
                   const std::string& obstacles = "") {
    Write("models/bot.yaml",
          "model: bot\n"
          "objects:\n"
          "  name: body\n"
          "  type: shape\n" +
              shape_keys);
    const fs::path world = Write(
        "world.yaml", "simulation: {physics: ode, time_step: 0.01}\n" + obstacles +
                          "models: [{model: models/bot.yaml, count: " + std::to_string(count) +
                          ", distribute: {region: {min: [-20, -20], max: [20, 20]}}}]\n");
    return LoadWorld(world, {}, registry_);
  }
  std::string ErrorOf(const std::string& shape_keys) {
    try {
      Load(shape_keys);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }

  ModuleRegistry registry_;
  fs::path dir_;
};

TEST_F(LoaderMeshTest, HundredCopiesShareOneAsset) {
  const LoadedWorld w = Load("  shape: mesh\n  file: cube.stl\n  scale: [0.1, 0.2, 0.3]\n", 100);
  const Scene& scene = w.world->scene();
  ASSERT_EQ(scene.instances().size(), 100u);
  std::set<const TriangleMesh*> assets;
  std::set<const ShapeData*> settings;
  for (const ShapeData& s : scene.shapes()) {
    EXPECT_EQ(s.kind, ShapeKind::kMesh);
    assets.insert(s.mesh.get());
    settings.insert(&s);
  }
  ASSERT_EQ(assets.size(), 1u);
  EXPECT_EQ(settings.size(), 1u);  // the copies share their shape's settings, asset and all
  const auto& mesh = scene.shapes()[0].mesh;
  // The ASCII STL's 36 corners weld into a closed cube of 8 vertices, scaled.
  EXPECT_EQ(mesh->vertices().size(), 8u);
  EXPECT_EQ(mesh->triangles().size(), 12u);
  EXPECT_TRUE(mesh->closed());
  EXPECT_NEAR(mesh->hi().x, 0.05, 1e-12);
  EXPECT_NEAR(mesh->hi().z, 0.15, 1e-12);
  EXPECT_NEAR(scene.shapes()[0].size.y, 0.2, 1e-12);
  // Placed standing on the ground: the bottom face at z = 0.
  EXPECT_NEAR(scene.world_pose(scene.instances()[0].root).p.z, 0.15, 1e-9);
}

TEST_F(LoaderMeshTest, ObstacleMeshIsRelativeToTheWorldFileAndSharedWithModels) {
  const LoadedWorld w =
      Load("  shape: mesh\n  file: ../tetra.stl\n", 2,
           "obstacles:\n"
           "  - {name: rock, shape: mesh, file: tetra.stl, position: [30, 0, 0]}\n"
           "  - {name: rock2, shape: mesh, file: tetra.stl, position: [-30, 0, 0],"
           " scale: [2, 2, 2]}\n");
  const Scene& scene = w.world->scene();
  const ShapeData& rock = scene.shape(scene.FindObject("/rock"));
  const ShapeData& rock2 = scene.shape(scene.FindObject("/rock2"));
  EXPECT_TRUE(rock.mesh->closed());
  EXPECT_EQ(rock.mesh->triangles().size(), 4u);
  EXPECT_NEAR(rock2.mesh->hi().x, 2, 1e-12);
  // Same file and scale: one asset, for the obstacle and the models alike.
  for (const ModelInstance& inst : scene.instances())
    EXPECT_EQ(scene.shape(inst.root).mesh.get(), rock.mesh.get());
}

TEST_F(LoaderMeshTest, MistakesNameTheFileAndThePlace) {
  std::string e = ErrorOf("  shape: mesh\n  file: missing.stl\n");
  EXPECT_NE(e.find("bot.yaml:6:9: mesh file 'missing.stl' not found"), std::string::npos) << e;
  e = ErrorOf("  shape: mesh\n");
  EXPECT_NE(e.find("'file'"), std::string::npos) << e;
  Write("models/part.ply", "ply\n");
  e = ErrorOf("  shape: mesh\n  file: part.ply\n");
  EXPECT_NE(e.find("mesh file 'part.ply' must be STL, OBJ or COLLADA"), std::string::npos) << e;
  Write("models/empty.stl", "");
  e = ErrorOf("  shape: mesh\n  file: empty.stl\n");
  EXPECT_NE(e.find("bot.yaml:6:9: mesh file 'empty.stl' is empty"), std::string::npos) << e;
  Write("models/lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n");
  e = ErrorOf("  shape: mesh\n  file: lines.obj\n");
  EXPECT_NE(e.find("lines.obj"), std::string::npos) << e;
  EXPECT_NE(e.find("no triangles"), std::string::npos) << e;
  Write("models/junk.stl", "solid x\n  facet normal oops\n");
  e = ErrorOf("  shape: mesh\n  file: junk.stl\n");
  EXPECT_NE(e.find("bot.yaml:6:9: "), std::string::npos) << e;
  EXPECT_NE(e.find("junk.stl"), std::string::npos) << e;
  e = ErrorOf("  shape: mesh\n  file: cube.stl\n  size: [1, 1, 1]\n");
  EXPECT_NE(e.find("'size' does not apply to a mesh"), std::string::npos) << e;
  e = ErrorOf("  shape: box\n  size: [1, 1, 1]\n  file: cube.stl\n");
  EXPECT_NE(e.find("'file' does not apply to a box"), std::string::npos) << e;
  e = ErrorOf("  shape: mesh\n  flie: cube.stl\n");
  EXPECT_NE(e.find("did you mean 'file'"), std::string::npos) << e;
  e = ErrorOf("  shape: mesh\n  file: cube.stl\n  scale: [1, 0, 1]\n");
  EXPECT_NE(e.find("scale"), std::string::npos) << e;
  e = ErrorOf("  shape: mseh\n");
  EXPECT_NE(e.find("did you mean 'mesh'"), std::string::npos) << e;
}

TEST_F(LoaderMeshTest, ObjFilesLoadToo) {
  Write("models/quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  const LoadedWorld w = Load("  shape: mesh\n  file: quad.obj\n");
  const ShapeData& s = w.world->scene().shapes()[0];
  EXPECT_EQ(s.mesh->triangles().size(), 2u);  // the quad, triangulated
  EXPECT_FALSE(s.mesh->closed());
}

// Two one-triangle meshes (as left by an STL whose other facet has no area)
// colliding under ODE: its mesh collider dereferenced null on them.
TEST_F(LoaderMeshTest, OneTriangleMeshesCollideUnderOde) {
  Write("tri.stl",
        "solid m\n"
        "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\n"
        "endloop\nendfacet\n"
        "facet normal 0 0 1\nouter loop\nvertex 1 1 1\nvertex 1 1 1\nvertex 1 1 1\n"
        "endloop\nendfacet\n"
        "endsolid m\n");
  const fs::path world =
      Write("tri_world.yaml",
            "simulation: {physics: ode, steps: 3}\n"
            "obstacles:\n"
            "  - {shape: mesh, file: tri.stl, position: [0, 0, 0.05]}\n"
            "  - {shape: mesh, file: tri.stl, dynamic: true, mass: 1, position: [1, 1, 0.5]}\n");
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadedWorld w = LoadWorld(world, {}, registry);
  ASSERT_EQ(w.world->scene().shapes().size(), 2u);
  for (int i = 0; i < 3; ++i) w.world->Step();
  EXPECT_EQ(w.world->step_count(), 3);
}

}  // namespace
}  // namespace swarmsim
