// The joint type (framework/types/joint_type.cc): the keys a model file
// gives a joint, the mistakes it refuses at their file:line:column, how a
// joint scales with its model, and its rows: settings shared by the copies
// of one model entry (copy on write), state per copy, through world files
// as a user writes them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/types/core_types.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fake_reader.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;
using testing::FakeReader;

JointData Read(const FakeReader& reader) {
  JointData joint;
  kJointType.read(kJointType, reader, &joint);
  return joint;
}

TEST(JointTypeTest, WithoutKeysAJointIsAVelocityDrivenRevoluteJoint) {
  const JointData j = Read(FakeReader{});
  EXPECT_EQ(j.type(), JointType::kRevolute);
  EXPECT_EQ(j.mode(), JointMode::kVelocity);
  EXPECT_EQ(j.settings->max_force, 10);
  EXPECT_EQ(j.settings->max_velocity, 10);
  EXPECT_EQ(j.position, 0);
  EXPECT_TRUE(std::isinf(j.settings->min_position) && j.settings->min_position < 0);
  EXPECT_TRUE(std::isinf(j.settings->max_position) && j.settings->max_position > 0);
  EXPECT_EQ(j.depends(), nullptr);
  EXPECT_FALSE(j.ik_frozen);
  // The documented defaults are those values.
  for (const ObjectKey& key : kJointType.keys) {
    const std::string name = key.name;
    if (name == "joint") {
      EXPECT_STREQ(key.default_text, "revolute");
    } else if (name == "mode") {
      EXPECT_STREQ(key.default_text, "velocity");
    } else if (name == "max_force" || name == "max_velocity") {
      EXPECT_STREQ(key.default_text, "10");
    }
  }
}

TEST(JointTypeTest, EveryKeyReachesTheRow) {
  const JointData j = Read(FakeReader{{"joint", std::string("prismatic")},
                                      {"mode", std::string("position")},
                                      {"max_force", 40.0},
                                      {"max_velocity", 0.5},
                                      {"target_velocity", -1.0},
                                      {"target_position", 0.2},
                                      {"initial_position", 0.1},
                                      {"target_force", 3.0},
                                      {"damping", 0.7},
                                      {"limits", std::vector<double>{-0.3, 0.4}},
                                      {"ik", std::string("frozen")}});
  EXPECT_EQ(j.type(), JointType::kPrismatic);
  EXPECT_EQ(j.mode(), JointMode::kPosition);
  EXPECT_EQ(j.settings->max_force, 40);
  EXPECT_EQ(j.settings->max_velocity, 0.5);
  EXPECT_EQ(j.target_velocity, -1);
  EXPECT_EQ(j.target_position, 0.2);
  EXPECT_EQ(j.position, 0.1);  // initial_position is where the joint starts
  EXPECT_EQ(j.target_force, 3);
  EXPECT_EQ(j.settings->damping, 0.7);
  EXPECT_EQ(j.settings->min_position, -0.3);
  EXPECT_EQ(j.settings->max_position, 0.4);
  EXPECT_TRUE(j.ik_frozen);
  const std::pair<const char*, JointType> kinds[] = {{"revolute", JointType::kRevolute},
                                                     {"spherical", JointType::kSpherical},
                                                     {"fixed", JointType::kFixed}};
  for (const auto& [name, type] : kinds)
    EXPECT_EQ(Read(FakeReader{{"joint", std::string(name)}}).type(), type) << name;
  const std::pair<const char*, JointMode> modes[] = {{"passive", JointMode::kPassive},
                                                     {"velocity", JointMode::kVelocity},
                                                     {"force", JointMode::kForce}};
  for (const auto& [name, mode] : modes)
    EXPECT_EQ(Read(FakeReader{{"mode", std::string(name)}}).mode(), mode) << name;
}

TEST(JointTypeTest, AScrewJointNeedsAFiniteNonzeroPitchAndOnlyItHasOne) {
  const JointData screw = Read(FakeReader{{"joint", std::string("screw")}, {"pitch", 0.01}});
  EXPECT_EQ(screw.type(), JointType::kScrew);
  EXPECT_EQ(screw.settings->pitch, 0.01);
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"joint", std::string("screw")}});
            }),
            "model.yaml:2:1: a screw joint needs 'pitch' (m of travel per rad, nonzero)");
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"joint", std::string("screw")}, {"pitch", 0.0}});
            }),
            "model.yaml:3:3: 'pitch' must be a finite, nonzero number of m per rad");
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"pitch", 0.01}});
            }),
            "model.yaml:2:1: 'pitch' is for screw joints (joint: screw)");
}

TEST(JointTypeTest, ADependentJointNamesItsMasterByPath) {
  const JointData j =
      Read(FakeReader{{"master", std::string(":/leftWheel")}, {"factor", -1.0}, {"offset", 0.25}});
  ASSERT_NE(j.depends(), nullptr);
  EXPECT_EQ(j.depends()->master, ":/leftWheel");
  EXPECT_EQ(j.depends()->factor, -1);
  EXPECT_EQ(j.depends()->offset, 0.25);
  EXPECT_EQ(j.depends()->where, "model.yaml:2:3");  // errors about the master point here
  const JointData plain = Read(FakeReader{{"master", std::string("/base/j")}});
  EXPECT_EQ(plain.depends()->factor, 1);
  EXPECT_EQ(plain.depends()->offset, 0);
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"master", std::string("leftWheel")}});
            }),
            "model.yaml:2:3: 'leftWheel' is not a joint path: start with '/' (absolute), ':' "
            "(this model) or './' (below this joint)");
  for (const char* key : {"factor", "offset"})
    EXPECT_EQ(ErrorOf([&] {
                Read(FakeReader{{key, 2.0}});
              }),
              std::string("model.yaml:2:1: '") + key + "' is for dependent joints: add 'master'");
}

TEST(JointTypeTest, LimitsMustBeOrderedAndForcesPositive) {
  EXPECT_EQ(ErrorOf([] {
              Read(FakeReader{{"limits", std::vector<double>{1, -1}}});
            }),
            "model.yaml:2:3: 'limits' must be [min, max] with min <= max");
  const JointData pinned = Read(FakeReader{{"limits", std::vector<double>{0.5, 0.5}}});
  EXPECT_EQ(pinned.settings->min_position, 0.5);
  EXPECT_EQ(pinned.settings->max_position, 0.5);
  // A joint may not start past its own stops (ODE snapped it back with a jolt).
  EXPECT_EQ(
      ErrorOf([] {
        Read(FakeReader{{"limits", std::vector<double>{-0.5, 1}}, {"initial_position", 1.25}});
      }),
      "model.yaml:3:3: 'initial_position' 1.25 is outside 'limits' [-0.5, 1]");
  EXPECT_EQ(Read(FakeReader{{"limits", std::vector<double>{-0.5, 1}}, {"initial_position", 1.0}})
                .position,
            1.0);
  EXPECT_CONTAINS(ErrorOf([] { Read(FakeReader{{"max_force", 0.0}}); }), "a positive number");
  EXPECT_CONTAINS(ErrorOf([] { Read(FakeReader{{"damping", -1.0}}); }), "a non-negative number");
  EXPECT_CONTAINS(ErrorOf([] {
                    Read(FakeReader{{"joint", std::string("hinge")}});
                  }),
                  "not 'hinge'");
}

// A revolute joint's torques scale with s^4 and its angles not at all; a
// screw's pitch and a prismatic follower's offset are lengths.
TEST(JointTypeTest, ScalingKeepsAnglesAndScalesLengthsForcesAndDamping) {
  Scene scene;
  const ObjectId root = scene.AddDummy("bot", {}, {});
  JointData hinge;
  hinge.position = 0.5;
  hinge.settings.Edit().max_force = 2;
  hinge.target_force = 1;
  hinge.settings.Edit().damping = 0.1;
  const ObjectId h = scene.AddJoint("hinge", root, {}, hinge);
  JointData screw;
  screw.settings.Edit().type = JointType::kScrew;
  screw.settings.Edit().pitch = 0.01;
  const ObjectId s = scene.AddJoint("screw", root, {}, screw);
  JointData slide;
  slide.settings.Edit().type = JointType::kPrismatic;
  slide.settings.Edit().damping = 0.3;
  slide.target_force = 5;
  auto dependency = std::make_shared<JointDependency>();
  dependency->master = "/bot/hinge";
  dependency->factor = 0.2;
  dependency->offset = 0.05;
  slide.settings.Edit().depends = dependency;
  const ObjectId p = scene.AddJoint("slide", root, {}, slide);
  JointData turn;
  turn.settings.Edit().depends = dependency;
  const ObjectId t = scene.AddJoint("turn", root, {}, turn);

  scene.ScaleSubtree(root, 2);
  EXPECT_EQ(scene.joint(h).position, 0.5);
  EXPECT_DOUBLE_EQ(scene.joint(h).settings->max_force, 32);
  EXPECT_DOUBLE_EQ(scene.joint(h).target_force, 16);
  EXPECT_DOUBLE_EQ(scene.joint(h).settings->damping, 1.6);
  EXPECT_DOUBLE_EQ(scene.joint(s).settings->pitch, 0.02);
  EXPECT_DOUBLE_EQ(scene.joint(p).settings->damping, 1.2);  // N s/m: s^2
  EXPECT_DOUBLE_EQ(scene.joint(p).target_force, 40);
  EXPECT_DOUBLE_EQ(scene.joint(p).depends()->offset, 0.1);
  EXPECT_EQ(scene.joint(p).depends()->factor, 0.2);
  EXPECT_EQ(scene.joint(t).depends()->offset, 0.05);  // radians stay
  // The shared dependency itself is untouched (another copy may use it).
  EXPECT_EQ(dependency->offset, 0.05);
}

namespace fs = std::filesystem;

// An empty folder of this process under the temporary folder.
fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Kinematic physics moves joints to their targets, and at their speed,
// within their limits: a target past a limit stops at it (it was reached,
// a Panda's joint1 at 5 rad against its 2.9).
TEST(JointLimitsTest, KinematicJointsStopAtTheirLimits) {
  const fs::path dir = FreshDir("swarmsim_joint_limits");
  std::ofstream(dir / "bot.yaml")
      << "model: bot\n"
         "objects:\n"
         "  name: body\n"
         "  type: dummy\n"
         "  script: bot.lua\n"
         "  children:\n"
         "    - {name: arm, type: joint, mode: position, max_velocity: 1, limits: [-0.5, 0.8]}\n"
         "    - {name: spin, type: joint, limits: [-1, 0.4]}\n"
         "    - {name: wheel, type: joint}\n";
  std::ofstream(dir / "bot.lua") << "function sysCall_actuation()\n"
                                    "  local s = sim.getSimulationTime() < 2 and 1 or -1\n"
                                    "  sim.setJointTargetPosition(sim.getObject(':/arm'), 3 * s)\n"
                                    "  sim.setJointTargetVelocity(sim.getObject(':/spin'), s)\n"
                                    "  sim.setJointTargetVelocity(sim.getObject(':/wheel'), s)\n"
                                    "end\n";
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                       "models: [{model: bot.yaml, position: [0, 0]}]\n";
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadedWorld loaded = LoadWorld(dir / "world.yaml", LoadOptions{}, registry);
  World& world = *loaded.world;
  const auto joint = [&](const char* name) -> const JointData& {
    return world.scene().joint(world.scene().FindObject(name, world.scene().instance(0).root));
  };
  world.Start();
  for (int i = 0; i < 20; ++i) world.Step();  // 2 s driven up
  EXPECT_DOUBLE_EQ(joint("./arm").position, 0.8);
  EXPECT_DOUBLE_EQ(joint("./spin").position, 0.4);
  EXPECT_EQ(joint("./spin").velocity, 0) << "held at its limit";
  EXPECT_NEAR(joint("./wheel").position, 2.0, 1e-9) << "no limits: not held";
  for (int i = 0; i < 30; ++i) world.Step();  // 3 s driven down
  EXPECT_DOUBLE_EQ(joint("./arm").position, -0.5);
  EXPECT_DOUBLE_EQ(joint("./spin").position, -1);
  EXPECT_NEAR(joint("./wheel").position, -1.0, 1e-9);
  fs::remove_all(dir);
}

// Two entries of one model on kinematic physics: three robots (the second
// with its own max_force, through `instances:`) and one more with another
// entry's max_force. Every robot's script drives its wheel and its slide
// every step; at its 4th step, bot#2's script doubles its size (a
// prismatic joint's limits and speed are lengths), and bot#3's copies its
// robot.
class JointSettingsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = FreshDir("swarmsim_joint_type");
    std::ofstream(dir_ / "bot.yaml")
        << "model: bot\n"
           "parameters: {force: {default: 5}}\n"
           "objects:\n"
           "  name: body\n"
           "  type: dummy\n"
           "  script: bot.lua\n"
           "  children:\n"
           "    - {name: wheel, type: joint, max_force: $force, damping: 0.2}\n"
           "    - {name: slide, type: joint, joint: prismatic, mode: position,\n"
           "       max_velocity: 0.5, limits: [-0.2, 0.3]}\n";
    std::ofstream(dir_ / "bot.lua")
        << "local wheel, slide, root, steps = nil, nil, nil, 0\n"
           "function sysCall_init()\n"
           "  wheel = sim.getObject(':/wheel')\n"
           "  slide = sim.getObject(':/slide')\n"
           "  root = sim.getObject(':')\n"
           "end\n"
           "function sysCall_actuation()\n"
           "  sim.setJointTargetVelocity(wheel, 1 + sim.getRobotIndex())\n"
           "  sim.setJointTargetPosition(slide, 0.1)\n"
           "  steps = steps + 1\n"
           "  if steps ~= 4 then return end\n"
           "  if sim.getRobotName() == 'bot#2' then sim.setObjectSizeFactor(root, 2) end\n"
           "  if sim.getRobotName() == 'bot#3' then sim.copyModel(root, {0, 5, 0}) end\n"
           "end\n";
    std::ofstream(dir_ / "world.yaml")
        << "simulation: {physics: kinematic, time_step: 0.1}\n"
           "models:\n"
           "  - {model: bot.yaml, count: 3, distribute: {region: {min: [-10, -2], max: [-4, 2]}},\n"
           "     instances: [{index: 1, parameters: {force: 7}}]}\n"
           "  - {model: bot.yaml, position: [0, 0], parameters: {force: 9}}\n";
    RegisterBuiltinModules(&registry_);
    loaded_ = LoadWorld(dir_ / "world.yaml", LoadOptions{}, registry_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Scene& scene() { return loaded_.world->scene(); }
  const JointData& Row(int robot, const char* name) {
    return scene().joint(scene().FindObject(name, scene().instance(robot).root));
  }

  fs::path dir_;
  ModuleRegistry registry_;
  LoadedWorld loaded_;
};

TEST_F(JointSettingsTest, CopiesOfOneModelEntryShareTheirSettings) {
  ASSERT_EQ(scene().instances().size(), 4u);
  for (const char* name : {"./wheel", "./slide"}) {
    SCOPED_TRACE(name);
    EXPECT_TRUE(Row(2, name).settings.SameAs(Row(0, name).settings));
    // A copy with its own values has its own settings; so has another entry.
    EXPECT_FALSE(Row(1, name).settings.SameAs(Row(0, name).settings));
    EXPECT_FALSE(Row(3, name).settings.SameAs(Row(0, name).settings));
  }
  EXPECT_EQ(Row(0, "./wheel").settings->max_force, 5);
  EXPECT_EQ(Row(1, "./wheel").settings->max_force, 7);
  EXPECT_EQ(Row(3, "./wheel").settings->max_force, 9);
  EXPECT_EQ(Row(2, "./wheel").settings->damping, 0.2);
  // Two joints of one model are two settings.
  EXPECT_FALSE(Row(0, "./wheel").settings.SameAs(Row(0, "./slide").settings));
  EXPECT_EQ(Row(0, "./slide").type(), JointType::kPrismatic);
  EXPECT_EQ(Row(0, "./slide").mode(), JointMode::kPosition);
}

TEST_F(JointSettingsTest, StepsWriteStateOnly) {
  loaded_.world->Start();
  const uint64_t hash = loaded_.world->StateHash();
  for (int k = 0; k < 3; ++k) loaded_.world->Step();  // before the scripts' edits
  EXPECT_NE(loaded_.world->StateHash(), hash);
  // Each robot's own targets and positions (velocity mode: its target; position mode: at up
  // to 0.5 m/s toward 0.1 m).
  for (int robot : {0, 1, 2, 3}) {
    SCOPED_TRACE(robot);
    EXPECT_EQ(Row(robot, "./wheel").target_velocity, 1 + robot);
    EXPECT_GT(Row(robot, "./wheel").position, 0);
    EXPECT_NEAR(Row(robot, "./slide").position, 0.1, 1e-9);
  }
  EXPECT_NE(Row(0, "./wheel").position, Row(1, "./wheel").position);
  // Stepping wrote state only: the copies still share their settings.
  for (const char* name : {"./wheel", "./slide"})
    EXPECT_TRUE(Row(2, name).settings.SameAs(Row(0, name).settings)) << name;
}

TEST_F(JointSettingsTest, AScriptsEditGivesItsCopyItsOwnSettings) {
  loaded_.world->Start();
  for (int k = 0; k < 4; ++k) loaded_.world->Step();  // bot#2 doubles its size
  const JointData& slide = Row(2, "./slide");
  EXPECT_FALSE(slide.settings.SameAs(Row(0, "./slide").settings));
  EXPECT_DOUBLE_EQ(slide.settings->max_velocity, 1.0);  // m/s: x 2
  EXPECT_DOUBLE_EQ(slide.settings->min_position, -0.4);
  EXPECT_DOUBLE_EQ(slide.settings->max_position, 0.6);
  EXPECT_DOUBLE_EQ(Row(2, "./wheel").settings->max_force, 80);  // N m: x 2^4
  EXPECT_DOUBLE_EQ(Row(2, "./wheel").settings->damping, 3.2);
  // The copy it shared them with keeps its own values.
  EXPECT_DOUBLE_EQ(Row(0, "./slide").settings->max_velocity, 0.5);
  EXPECT_DOUBLE_EQ(Row(0, "./slide").settings->max_position, 0.3);
  EXPECT_DOUBLE_EQ(Row(0, "./wheel").settings->max_force, 5);
  EXPECT_DOUBLE_EQ(Row(0, "./wheel").settings->damping, 0.2);
  // The scaled copy keeps its other settings.
  EXPECT_EQ(slide.type(), JointType::kPrismatic);
  EXPECT_EQ(slide.mode(), JointMode::kPosition);
}

TEST_F(JointSettingsTest, ARunTimeCopySharesItsSourcesSettings) {
  loaded_.world->Start();
  for (int k = 0; k < 4; ++k) loaded_.world->Step();  // bot#3 copies itself
  ASSERT_EQ(scene().instances().size(), 5u);
  for (const char* name : {"./wheel", "./slide"}) {
    SCOPED_TRACE(name);
    EXPECT_TRUE(Row(4, name).settings.SameAs(Row(3, name).settings));
    EXPECT_FALSE(Row(4, name).settings.SameAs(Row(0, name).settings));
  }
  EXPECT_EQ(Row(4, "./wheel").settings->max_force, 9);
  // Its state is its own: it runs its script from the next step.
  loaded_.world->Step();
  EXPECT_EQ(Row(4, "./wheel").target_velocity, 5);
  EXPECT_EQ(Row(3, "./wheel").target_velocity, 4);
  EXPECT_TRUE(Row(4, "./wheel").settings.SameAs(Row(3, "./wheel").settings));
}

}  // namespace
}  // namespace swarmsim
