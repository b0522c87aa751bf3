// `ik_groups:` in model files (modules/kinematics/ik_model_section.cc, a
// model-file section the loader reads through the registry): read, copied
// with each robot, driven from Lua with sim.handleIkGroup; mistakes
// reported with file:line:column and the nearest known name.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/kinematics/ik_groups.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

// A planar 2-link arm, its target under the root; `{groups}` is replaced.
constexpr const char* kArm = R"(model: arm
objects:
  name: base
  type: dummy
  script: arm.lua
  children:
    - {name: target, type: dummy, position: [0.6, 0.3, 0]}
    - name: j1
      type: joint
      mode: passive
      children:
        - name: j2
          type: joint
          mode: passive
          position: [0.5, 0, 0]
          initial_position: 0.3
          children:
            - {name: tip, type: dummy, position: [0.4, 0, 0]}
ik_groups:
)";

class IkModelSectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RegisterBuiltinModules(&registry_);
    dir_ = fs::temp_directory_path() /
           ("swarmsim_ik_model_section_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  LoadedWorld Load(const std::string& groups, const std::string& script = "", int count = 3) {
    Write("arm.yaml", std::string(kArm) + groups);
    Write("arm.lua", script);
    Write("world.yaml",
          "simulation: {physics: kinematic, time_step: 0.05}\n"
          "arena: {size: 20}\n"
          "models: [{model: arm.yaml, count: " +
              std::to_string(count) + ", distribute: {region: arena}}]\n");
    LoadedWorld loaded = LoadWorld(dir_ / "world.yaml", {}, registry_);
    loaded.world->set_log_sink([this](std::string_view line) { log_ += std::string(line) + "\n"; });
    return loaded;
  }
  std::string ErrorOf(const std::string& groups) {
    try {
      Load(groups);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }

  ModuleRegistry registry_;
  fs::path dir_;
  std::string log_;
};

TEST_F(IkModelSectionTest, EveryCopyGetsItsGroupAndItSolvesEachStep) {
  LoadedWorld loaded = Load(
      "  - {name: reach, tips: [{tip: j1/j2/tip, target: target, constraints: [x, y]}], "
      "iterations: 50, tolerance: 1.0e-6}\n");
  World& world = *loaded.world;
  auto* ik = kinematics::FindIkGroups(world);
  ASSERT_NE(ik, nullptr);
  EXPECT_EQ(ik->live_group_count(), 3);
  world.Step();
  const Scene& scene = world.scene();
  for (int r = 0; r < 3; ++r) {
    const ObjectId root = scene.instance(r).root;
    const ObjectId tip = scene.FindObject("./tip", root),
                   target = scene.FindObject("./target", root);
    EXPECT_LT((scene.world_pose(tip).p - scene.world_pose(target).p).Norm(), 1e-5) << r;
    EXPECT_EQ(scene.linked_dummy(tip), target);
  }
}

TEST_F(IkModelSectionTest, ScriptsHandleTheirOwnGroupExplicitly) {
  LoadedWorld loaded = Load(
      "  - {name: reach, tips: [{tip: j1/j2/tip, target: target, constraints: position}], "
      "automatic: false, iterations: 50}\n",
      "function sysCall_actuation()\n"
      "  local g = sim.getIkGroup('reach')\n"
      "  print(sim.getIkGroupStatus(g), sim.handleIkGroup(g), sim.ikresult_success)\n"
      "end\n",
      1);
  loaded.world->Step();
  EXPECT_EQ(log_, "[arm#0] 0\t1\t1\n");
}

// A handle is not taken modulo 2^32: g + 2^32 is no group.
TEST_F(IkModelSectionTest, HandlesBeyondTheIntRangeAreNoGroup) {
  LoadedWorld loaded =
      Load("  - {name: reach, tips: [{tip: j1/j2/tip, target: target}], automatic: false}\n",
           "function sysCall_actuation()\n"
           "  print(pcall(sim.handleIkGroup, sim.getIkGroup('reach') + (1 << 32)))\n"
           "end\n",
           1);
  loaded.world->Step();
  EXPECT_NE(log_.find("[arm#0] false\t"), std::string::npos) << log_;
  EXPECT_NE(log_.find("no IK group with handle 42949672"), std::string::npos) << log_;
}

// The README's `weights: {path: w}`, in flow and block form: weight 0
// freezes j1, so only j2 moves; with no weights both do.
TEST_F(IkModelSectionTest, WeightsFromTheModelFileChangeTheSolution) {
  const auto joints_after_a_step = [&](const std::string& weights) {
    LoadedWorld loaded = Load(
        "  - name: reach\n"
        "    tips: [{tip: j1/j2/tip, target: target, constraints: [x, y]}]\n"
        "    iterations: 20\n" +
            weights,
        "", 1);
    loaded.world->Step();
    const Scene& scene = loaded.world->scene();
    const ObjectId root = scene.instance(0).root;
    return std::pair(scene.joint(scene.FindObject("./j1", root)).position,
                     scene.joint(scene.FindObject("./j1/j2", root)).position);
  };
  const auto [free1, free2] = joints_after_a_step("");
  EXPECT_NE(free1, 0.0);
  for (const std::string weights :
       {"    weights: {j1: 0, j1/j2: 1}\n", "    weights:\n      j1: 0\n      j1/j2: 0.5\n"}) {
    const auto [frozen1, moved2] = joints_after_a_step(weights);
    EXPECT_EQ(frozen1, 0.0) << weights;
    EXPECT_NE(moved2, 0.3) << weights;  // its initial position
    EXPECT_NE(moved2, free2) << weights;
  }
}

TEST_F(IkModelSectionTest, MistakesNameTheLineAndTheNearestName) {
  const std::string bad_path =
      ErrorOf("  - {name: reach, tips: [{tip: j1/j2/tpi, target: target}]}\n");
  EXPECT_NE(bad_path.find("arm.yaml:20:"), std::string::npos) << bad_path;
  EXPECT_NE(bad_path.find("no object 'j1/j2/tpi'"), std::string::npos) << bad_path;
  EXPECT_NE(bad_path.find("did you mean 'j1/j2/tip'"), std::string::npos) << bad_path;
  const std::string bad_key = ErrorOf("  - {name: reach, dampnig: 1, tips: []}\n");
  EXPECT_NE(bad_key.find("did you mean 'damping'"), std::string::npos) << bad_key;
  const std::string bad_constraint = ErrorOf(
      "  - {name: reach, tips: [{tip: j1/j2/tip, target: target, constraints: [x, yy]}]}\n");
  EXPECT_NE(bad_constraint.find("arm.yaml:20:"), std::string::npos) << bad_constraint;
  const std::string no_joints =
      ErrorOf("  - {name: reach, tips: [{tip: target, target: j1/j2/tip}]}\n");
  EXPECT_NE(no_joints.find("no joint between"), std::string::npos) << no_joints;
}

}  // namespace
}  // namespace swarmsim
