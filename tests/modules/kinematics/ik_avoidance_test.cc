// IK obstacle avoidance, joint IK modes and spherical joints in world files:
// the example arms (worlds/ik_avoidance.yaml) keep their links clear of
// the post while reaching behind it, and cross it without `avoid`; the
// same hash at 1 and 2 threads; sim.setJointIkMode; mistakes at
// file:line:column (exit 2 from the program).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "framework/error.h"
#include "framework/world.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

using IkAvoidanceTest = testing::WorldDirTest;

const std::string kSource = SWARMSIM_SOURCE_DIR;

// Per robot, the least `links_to_post.distance` over `steps` steps, and
// each tip's distance to its target at the end.
struct ArmsRun {
  std::map<int, double> min_clearance, final_error;
};
ArmsRun RunArms(World* world, int steps) {
  ArmsRun run;
  for (int s = 0; s < steps; ++s) {
    world->Step();
    for (const MetricSample& m : world->TakeMetrics()) {
      if (m.name != "links_to_post.distance") continue;
      auto [it, added] = run.min_clearance.emplace(m.instance, m.value);
      if (!added) it->second = std::min(it->second, m.value);
    }
  }
  const Scene& scene = world->scene();
  for (int r = 0; r < static_cast<int>(scene.instances().size()); ++r) {
    const ObjectId root = scene.instance(r).root;
    run.final_error[r] = (scene.world_pose(scene.FindObject(":/tip", root)).p -
                          scene.world_pose(scene.FindObject(":/target", root)).p)
                             .Norm();
  }
  return run;
}

// Over the whole run (from the first solve on) every link stays at least
// its clearance from the post, less 5 mm (the distance is estimated to
// first order within a step and measured again each step), and every tip
// ends on its target behind the post.
TEST_F(IkAvoidanceTest, ExampleArmsKeepTheirLinksClearAndReachBehindThePost) {
  LoadedWorld loaded = LoadWorld(kSource + "/worlds/ik_avoidance.yaml", {}, registry_);
  loaded.world->set_log_sink([](std::string_view) {});
  const ArmsRun run = RunArms(loaded.world.get(), 300);  // 15 s
  const double clearance[3] = {0.05, 0.05, 0.1};
  ASSERT_EQ(run.min_clearance.size(), 3u);
  for (int r = 0; r < 3; ++r) {
    EXPECT_GE(run.min_clearance.at(r), clearance[r] - 0.005) << r;
    EXPECT_LT(run.final_error.at(r), 1e-3) << r;
  }
}

// The same arms without the `avoid` entry sweep their links through the
// post (the test above would fail for them), and reach all the same.
TEST_F(IkAvoidanceTest, WithoutAvoidanceTheSameArmsCrossThePost) {
  std::string model = testing::ReadFile(kSource + "/worlds/models/reach_arm.yaml");
  const size_t avoid = model.find("    avoid:");
  ASSERT_NE(avoid, std::string::npos);
  model.erase(avoid);
  const size_t script = model.find("  script: ");
  ASSERT_NE(script, std::string::npos);
  model.erase(script, model.find('\n', script) + 1 - script);
  std::filesystem::create_directories(dir_ / "models");
  Write("models/reach_arm.yaml", model);
  LoadedWorld loaded = Load(testing::ReadFile(kSource + "/worlds/ik_avoidance.yaml"));
  const ArmsRun run = RunArms(loaded.world.get(), 300);
  ASSERT_EQ(run.min_clearance.size(), 3u);
  for (int r = 0; r < 3; ++r) {
    EXPECT_LT(run.min_clearance.at(r), 0.005) << r;
    EXPECT_LT(run.final_error.at(r), 1e-3) << r;
  }
}

TEST_F(IkAvoidanceTest, ExampleHashIsTheSameAtOneAndTwoThreads) {
  uint64_t hashes[2] = {};
  for (int threads : {1, 2}) {
    LoadOptions options;
    options.threads = threads;
    LoadedWorld loaded = LoadWorld(kSource + "/worlds/ik_avoidance.yaml", options, registry_);
    loaded.world->set_log_sink([](std::string_view) {});
    for (int s = 0; s < 150; ++s) loaded.world->Step();
    hashes[threads - 1] = loaded.world->StateHash();
  }
  EXPECT_EQ(hashes[0], hashes[1]);
}

// A two-link arm with a post; `{joint2}` adds keys to its second joint and
// `{group}` to its IK group.
std::string ArmModel(const std::string& joint2, const std::string& group) {
  return "model: arm\n"
         "objects:\n"
         "  name: base\n"
         "  type: dummy\n"
         "  script: arm.lua\n"
         "  children:\n"
         "    - {name: post, type: shape, shape: cylinder, radius: 0.05, height: 0.2, position: "
         "[0.3, 0.3, 0]}\n"
         "    - {name: target, type: dummy, position: [0.6, 0.3, 0]}\n"
         "    - name: j1\n"
         "      type: joint\n"
         "      mode: passive\n"
         "      children:\n"
         "        - name: link1\n"
         "          type: shape\n"
         "          shape: box\n"
         "          size: [0.5, 0.04, 0.04]\n"
         "          position: [0.25, 0, 0]\n"
         "          children:\n"
         "            - name: j2\n"
         "              type: joint\n"
         "              mode: passive\n"
         "              position: [0.25, 0, 0]\n"
         "              initial_position: 0.3\n" +
         joint2 +
         "              children:\n"
         "                - {name: tip, type: dummy, position: [0.4, 0, 0]}\n"
         "ik_groups:\n"
         "  - name: reach\n"
         "    tips: [{tip: j1/link1/j2/tip, target: target, constraints: [x, y]}]\n" +
         group;
}

constexpr const char* kArmWorld =
    "simulation: {physics: kinematic, time_step: 0.05}\n"
    "models: [{model: arm.yaml, position: [0, 0]}]\n";

class IkAvoidanceErrorTest : public testing::WorldDirTest {
 protected:
  // The loader's message for the arm with these keys, or "(no error)".
  std::string ErrorOf(const std::string& joint2, const std::string& group) {
    Write("arm.yaml", ArmModel(joint2, group));
    Write("arm.lua", "");
    try {
      Load(kArmWorld);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
};

TEST_F(IkAvoidanceErrorTest, MistakesAreFileLineColumnErrors) {
  const std::string avoid =
      "    avoid: [{links: [j1/link1], collection: ':/post', distance: 0.05}]\n";
  EXPECT_EQ(ErrorOf("", avoid), "(no error)");
  // The group's lines are 28 and on.
  EXPECT_CONTAINS(ErrorOf("", "    avoid: [{links: [j1/link1], collection: ':/pots'}]\n"),
                  "arm.yaml:29:45: IK group 'reach', avoid: ':/pots' matches no object; did you "
                  "mean ':/post'?");
  EXPECT_CONTAINS(ErrorOf("", "    avoid: [{links: [j1/lnik1], collection: ':/post'}]\n"),
                  "arm.yaml:29:22: no object 'j1/lnik1' in model 'arm'; did you mean 'j1/link1'?");
  EXPECT_CONTAINS(
      ErrorOf("", "    avoid: [{links: [j1/link1], collection: ':/post', distance: -0.1}]\n"),
      "arm.yaml:29:65: 'distance' must be a positive number");
  EXPECT_CONTAINS(
      ErrorOf("", "    avoid: [{links: [j1/link1], collection: everything_else}]\n"),
      "arm.yaml:29:45: IK group 'reach', avoid: 'everything_else' would include the arm itself");
  EXPECT_CONTAINS(ErrorOf("", "    avoid: [{links: [j1/link1], colection: ':/post'}]\n"),
                  "did you mean 'collection'");
  // A spherical joint in a group that sets target positions.
  EXPECT_CONTAINS(ErrorOf("              joint: spherical\n", "    mode: targets\n"),
                  "arm.yaml:28:5:");
  EXPECT_CONTAINS(ErrorOf("              joint: spherical\n", "    mode: targets\n"),
                  "the spherical joint '/base/j1/link1/j2' can only be solved in direct mode");
  // A velocity-mode joint in such a group: it would ignore the targets.
  for (const std::string mode : {"targets", "direct"}) {
    std::string arm = ArmModel("", "    mode: " + mode + "\n");
    const std::string passive = "mode: passive\n              position: [0.25";
    arm.replace(arm.find(passive), 13, "mode: velocity");
    Write("arm.yaml", arm);
    Write("arm.lua", "");
    std::string error = "(no error)";
    try {
      Load(kArmWorld);
    } catch (const Error& e) {
      error = e.what();
    }
    if (mode == "targets")
      EXPECT_CONTAINS(error,
                      "the joint '/base/j1/link1/j2' is in velocity mode, which ignores the "
                      "target positions mode: targets sets");
    else
      EXPECT_EQ(error, "(no error)");
  }
  // A typo in a tip named by its bare name: the name suggested, not a path.
  {
    std::string arm = ArmModel("", "");
    const std::string tip = "tip: j1/link1/j2/tip";
    arm.replace(arm.find(tip), tip.size(), "tip: tpi");
    Write("arm.yaml", arm);
    std::string error = "(no error)";
    try {
      Load(kArmWorld);
    } catch (const Error& e) {
      error = e.what();
    }
    EXPECT_CONTAINS(error, "no object 'tpi' in model 'arm'; did you mean 'tip'?");
  }
  EXPECT_CONTAINS(ErrorOf("              ik: sometimes\n", ""), "arm.yaml:24:");
}

TEST_F(IkAvoidanceErrorTest, TheProgramExitsWithTwo) {
  Write("arm.yaml", ArmModel("", "    avoid: [{links: [j1/link1], collection: /nothing}]\n"));
  Write("arm.lua", "");
  const std::filesystem::path world = Write("world.yaml", kArmWorld);
  const testing::CommandResult r = testing::RunProgram("run " + world.string() + " --steps 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_CONTAINS(r.output,
                  "arm.yaml:29:45: IK group 'reach', avoid: '/nothing' matches no object");
}

// sim.setJointIkMode freezes the shoulder from the first step: the elbow
// alone moves towards the target; set active again, the shoulder moves.
TEST_F(IkAvoidanceErrorTest, ScriptsFreezeAndReleaseAJointForIk) {
  Write("arm.yaml", ArmModel("", "    iterations: 5\n"));
  Write("arm.lua",
        "local j1, steps = nil, 0\n"
        "function sysCall_init()\n"
        "  j1 = sim.getObject(':/j1')\n"
        "  sim.setJointIkMode(j1, sim.jointikmode_frozen)\n"
        "  assert(sim.getJointIkMode(j1) == sim.jointikmode_frozen)\n"
        "  assert(not pcall(sim.setJointIkMode, j1, 7))\n"
        "end\n"
        "function sysCall_actuation()\n"
        "  steps = steps + 1\n"
        "  if steps == 3 then sim.setJointIkMode(j1, sim.jointikmode_active) end\n"
        "end\n");
  LoadedWorld loaded = Load(kArmWorld);
  World& world = *loaded.world;
  const Scene& scene = world.scene();
  const ObjectId j1 = scene.FindObject("/arm#0/j1"), j2 = scene.FindObject("/arm#0/j1/link1/j2");
  world.Step();
  world.Step();
  EXPECT_EQ(scene.joint(j1).position, 0.0);
  EXPECT_NE(scene.joint(j2).position, 0.3);
  EXPECT_TRUE(scene.joint(j1).ik_frozen);
  world.Step();
  EXPECT_FALSE(scene.joint(j1).ik_frozen);
  EXPECT_NE(scene.joint(j1).position, 0.0);
}

}  // namespace
}  // namespace swarmsim
