// World files for 3D robots: physics ode/kinematic, capsules, spherical and
// fixed joints, force mode, limits — and the mistakes a user would make.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

class WorldLoader3dTest : public testing::WorldDirTest {
 protected:
  // Loads world.yaml placing one copy of arm.yaml (with `model` as its text).
  LoadedWorld LoadArm(const std::string& model, const std::string& physics = "ode") {
    Write("arm.yaml", model);
    const fs::path world =
        Write("world.yaml", "simulation: {physics: " + physics +
                                ", time_step: 0.01, physics_substeps: 2}\n"
                                "models: [{model: arm.yaml, position: [0, 0]}]\n");
    return LoadWorld(world, {}, registry_);
  }
  std::string ErrorOf(const std::string& model) {
    try {
      LoadArm(model);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }

  static constexpr const char* kArm =
      "model: arm\n"
      "objects:\n"
      "  name: base\n"
      "  type: shape\n"
      "  shape: box\n"
      "  size: [0.2, 0.2, 0.1]\n"
      "  position: [0, 0, 0.05]\n"
      "  children:\n"
      "    - name: shoulder\n"
      "      type: joint\n"
      "      joint: revolute\n"
      "      mode: force\n"
      "      target_force: 0.5\n"
      "      limits: [-0.5, 0.5]\n"
      "      position: [0, 0, 0.1]\n"
      "      children:\n"
      "        - name: link\n"
      "          type: shape\n"
      "          shape: capsule\n"
      "          radius: 0.02\n"
      "          height: 0.3\n"
      "          dynamic: true\n"
      "          mass: 0.5\n"
      "          position: [0, 0, 0.15]\n"
      "          children:\n"
      "            - {name: wrist, type: joint, joint: spherical, position: [0, 0, 0.15]}\n"
      "            - {name: weld, type: joint, joint: fixed, position: [0, 0, -0.15]}\n";
};

// A copy placed below ODE's ground is thrown up out of it by the contacts:
// the load says so, with the height that stands it on the ground; at that
// height, or with [x, y] alone, it says nothing.
TEST_F(WorldLoader3dTest, ACopyPlacedBelowTheGroundIsWarnedOf) {
  Write("dot.yaml",
        "model: dot\nobjects: {type: shape, shape: cylinder, radius: 0.05, height: 0.05, "
        "dynamic: true}\n");
  const auto warnings = [&](const std::string& position, const std::string& physics) {
    const fs::path world =
        Write("world.yaml", "simulation: {physics: " + physics +
                                "}\nmodels: [{model: dot.yaml, position: " + position + "}]\n");
    std::string all;
    for (const std::string& w : LoadWorld(world, {}, registry_).warnings) all += w + "\n";
    return all;
  };
  const std::string below = warnings("[0, 0, -1]", "ode");
  EXPECT_NE(below.find("world.yaml:2:38: this dot at z = -1 reaches 1.025 m below the ground "
                       "(z = 0 under physics: ode): the contacts will throw it up; give z >= "
                       "0.025"),
            std::string::npos)
      << below;
  for (const auto& [position, physics] :
       {std::pair{"[0, 0, 0.025]", "ode"}, {"[0, 0]", "ode"}, {"[0, 0, -1]", "box2d"}})
    EXPECT_EQ(warnings(position, physics).find("below the ground"), std::string::npos)
        << position << " " << physics;
}

TEST_F(WorldLoader3dTest, ReadsCapsulesJointTypesForceModeAndLimits) {
  LoadedWorld loaded = LoadArm(kArm);
  const Scene& scene = loaded.world->scene();
  const ObjectId link = scene.FindObject("/arm#0/shoulder/link");
  ASSERT_FALSE(link.IsNull());
  EXPECT_EQ(scene.shape(link).kind, ShapeKind::kCapsule);
  EXPECT_DOUBLE_EQ(scene.shape(link).size.z, 0.3);
  const JointData& shoulder = scene.joint(scene.FindObject("/arm#0/shoulder"));
  EXPECT_EQ(shoulder.mode(), JointMode::kForce);
  EXPECT_DOUBLE_EQ(shoulder.target_force, 0.5);
  EXPECT_DOUBLE_EQ(shoulder.settings->min_position, -0.5);
  EXPECT_DOUBLE_EQ(shoulder.settings->max_position, 0.5);
  EXPECT_EQ(scene.joint(scene.FindObject("/arm#0/shoulder/link/wrist")).type(),
            JointType::kSpherical);
  EXPECT_EQ(scene.joint(scene.FindObject("/arm#0/shoulder/link/weld")).type(), JointType::kFixed);
}

TEST_F(WorldLoader3dTest, OdeWorldRunsAndTheForceJointHitsItsLimit) {
  LoadedWorld loaded = LoadArm(kArm);
  World& world = *loaded.world;
  world.set_log_sink([](std::string_view) {});
  for (int i = 0; i < 200; ++i) world.Step();
  const ObjectId shoulder = world.scene().FindObject("/arm#0/shoulder");
  EXPECT_TRUE(world.scene().joint(shoulder).simulated);
  EXPECT_NEAR(world.scene().joint(shoulder).position, 0.5, 0.02);
}

// x, y, z, qx, qy, qz, qw.
std::array<double, 7> PoseValues(const Pose& X) {
  return {X.p.x, X.p.y, X.p.z, X.q.x, X.q.y, X.q.z, X.q.w};
}

// The ODE model loads unchanged under the other backends: the same objects,
// capsules kept as capsules (Box2D approximates them in its plane), and five
// steps leave every pose finite and the fixed base where it was placed. In
// kinematic worlds a force-mode joint does not move (no dynamics simulates it).
TEST_F(WorldLoader3dTest, KinematicAndBox2dWorldsAcceptTheSameModel) {
  const size_t objects = LoadArm(kArm).world->scene().object_count();
  for (const char* physics : {"kinematic", "box2d"}) {
    LoadedWorld loaded = LoadArm(kArm, physics);
    World& world = *loaded.world;
    world.set_log_sink([](std::string_view) {});
    const Scene& scene = world.scene();
    EXPECT_EQ(scene.object_count(), objects) << physics;
    const ObjectId link = scene.FindObject("/arm#0/shoulder/link");
    ASSERT_FALSE(link.IsNull()) << physics;
    EXPECT_EQ(scene.shape(link).kind, ShapeKind::kCapsule) << physics;
    const ObjectId base = scene.FindObject("/arm#0");
    const Vec3 p_base = scene.world_pose(base).p;
    for (int i = 0; i < 5; ++i) world.Step();
    EXPECT_NEAR(world.time(), 0.05, 1e-12) << physics;
    EXPECT_EQ(scene.world_pose(base).p.x, p_base.x) << physics;
    EXPECT_EQ(scene.world_pose(base).p.y, p_base.y) << physics;
    for (const char* path : {"/arm#0/shoulder", "/arm#0/shoulder/link",
                             "/arm#0/shoulder/link/wrist", "/arm#0/shoulder/link/weld"}) {
      for (double v : PoseValues(scene.world_pose(scene.FindObject(path)))) {
        EXPECT_TRUE(std::isfinite(v)) << physics << " " << path;
      }
    }
    if (std::string(physics) == "kinematic") {
      EXPECT_EQ(scene.joint(scene.FindObject("/arm#0/shoulder")).position, 0.0);
    }
  }
}

TEST_F(WorldLoader3dTest, MistakesNameFileLineAndSuggest) {
  auto replace = [](std::string text, const std::string& from, const std::string& to) {
    return text.replace(text.find(from), from.size(), to);
  };
  const std::string arm = kArm;
  std::string m = ErrorOf(replace(arm, "limits:", "limts:"));
  EXPECT_NE(m.find("arm.yaml:14:7:"), std::string::npos) << m;
  EXPECT_NE(m.find("did you mean 'limits'?"), std::string::npos) << m;
  m = ErrorOf(replace(arm, "joint: spherical", "joint: sphericle"));
  EXPECT_NE(m.find("arm.yaml:26:49:"), std::string::npos) << m;
  EXPECT_NE(m.find("spherical"), std::string::npos) << m;
  m = ErrorOf(replace(arm, "mode: force", "mode: torque"));
  EXPECT_NE(m.find("arm.yaml:12:"), std::string::npos) << m;
  EXPECT_NE(m.find("force"), std::string::npos) << m;
  m = ErrorOf(replace(arm, "height: 0.3", "height: 0.03"));
  EXPECT_NE(m.find("arm.yaml:21:"), std::string::npos) << m;
  EXPECT_NE(m.find("twice its radius"), std::string::npos) << m;
  m = ErrorOf(replace(arm, "limits: [-0.5, 0.5]", "limits: [0.5, -0.5]"));
  EXPECT_NE(m.find("min <= max"), std::string::npos) << m;
  m = ErrorOf(replace(arm, "shape: capsule", "shape: capsle"));
  EXPECT_NE(m.find("did you mean 'capsule'?"), std::string::npos) << m;
}

}  // namespace
}  // namespace swarmsim
