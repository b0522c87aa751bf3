// Screw joints, dependent joints (master, factor, offset) and
// sim.setJointPosition, through world and model files.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/world.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

constexpr double kDt = 0.05;
constexpr double kPitch = 0.02;

// A model's root dummy; its children follow (line 6 on).
constexpr const char* kBase = "model: rig\nobjects:\n  name: base\n  type: dummy\n  children:\n";

// A screw turning at 0.5 rad/s with a nut 0.1 m off its axis; a chain of
// dependent joints listed before their masters: a (prismatic) follows b,
// b follows c (velocity 0.3 rad/s) with a negative factor.
constexpr const char* kRig = R"(model: rig
objects:
  name: base
  type: dummy
  script: rig.lua
  children:
    - name: screw
      type: joint
      joint: screw
      pitch: 0.02
      target_velocity: 0.5
      children:
        - {name: nut, type: dummy, position: [0.1, 0, 0]}
    - name: a
      type: joint
      joint: prismatic
      master: ":/b"
      factor: 0.5
      offset: -0.05
      children:
        - {name: slider, type: dummy}
    - name: b
      type: joint
      master: ":/c"
      factor: -2
      offset: 0.1
    - name: c
      type: joint
      target_velocity: 0.3
    - name: free
      type: joint
      mode: passive
)";

class JointsTest : public testing::WorldDirTest {
 protected:
  LoadedWorld LoadRig(const std::string& script, int threads = 1,
                      const std::string& physics = "kinematic") {
    Write("rig.yaml", kRig);
    Write("rig.lua", script);
    return Load("simulation: {physics: " + physics +
                    ", time_step: 0.05}\n"
                    "models:\n"
                    "  - {model: rig.yaml, position: [1, 2, 0]}\n"
                    "  - {model: rig.yaml, position: [-1, 0, 0]}\n",
                threads);
  }
  static double Q(const World& world, const std::string& path) {
    const Scene& scene = world.scene();
    return scene.joint(scene.FindObject(path)).position;
  }
  // The error of w's next step, or "(no error)".
  static std::string StepError(LoadedWorld& w) {
    try {
      w.world->Step();
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
  // A model of one joint under a dummy (its keys `joint_keys`, indented as
  // a list item's) carrying a dynamic box, with `script`, under ODE.
  LoadedWorld LoadOdeArm(const std::string& joint_keys, const std::string& script) {
    Write("arm.yaml",
          "model: arm\nobjects:\n  name: base\n  type: dummy\n  script: arm.lua\n"
          "  children:\n    - name: m\n      type: joint\n      target_velocity: 0.5\n"
          "    - name: hinge\n      type: joint\n" +
              joint_keys +
              "      children:\n        - {name: link, type: shape, shape: box, size: [0.1, "
              "0.1, 0.1], dynamic: true, mass: 1}\n");
    Write("arm.lua", script);
    return Load(
        "simulation: {physics: ode, time_step: 0.02}\nmodels: [{model: arm.yaml, position: [0, 0, "
        "1]}]\n");
  }
  std::string LoadError(const std::string& rig) {
    Write("rig.yaml", rig);
    Write("rig.lua", "");
    try {
      Load("simulation: {physics: kinematic}\nmodels: [{model: rig.yaml, position: [0, 0]}]\n");
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
};

TEST_F(JointsTest, ScrewJointTurnsAndAdvancesByPitchTimesAngle) {
  LoadedWorld w = LoadRig("");
  const Scene& scene = w.world->scene();
  const ObjectId nut = scene.FindObject("/rig#0/nut");
  ASSERT_FALSE(nut.IsNull());
  for (int step = 1; step <= 40; ++step) {
    w.world->Step();
    const double q = Q(*w.world, "/rig#0/screw");
    EXPECT_NEAR(q, 0.5 * kDt * step, 1e-12);
    const Vec3 p = scene.world_pose(nut).p;
    EXPECT_NEAR(p.x, 1 + 0.1 * std::cos(q), 1e-12) << "step " << step;
    EXPECT_NEAR(p.y, 2 + 0.1 * std::sin(q), 1e-12) << "step " << step;
    EXPECT_NEAR(p.z, kPitch * q, 1e-12) << "step " << step;
  }
  EXPECT_GT(scene.world_pose(nut).p.z, 0.015);  // it did advance: 0.02 * 1 rad
}

TEST_F(JointsTest, DependentChainFollowsItsFormulaEveryStep) {
  LoadedWorld w = LoadRig("");
  const ObjectId slider = w.world->scene().FindObject("/rig#0/slider");
  ASSERT_FALSE(slider.IsNull());
  for (int step = 1; step <= 40; ++step) {
    w.world->Step();
    const double c = Q(*w.world, "/rig#0/c"), b = Q(*w.world, "/rig#0/b");
    const double a = Q(*w.world, "/rig#0/a");
    EXPECT_NEAR(c, 0.3 * kDt * step, 1e-12);
    EXPECT_DOUBLE_EQ(b, 0.1 - 2 * c) << "step " << step;  // this step's c, not the last
    EXPECT_DOUBLE_EQ(a, -0.05 + 0.5 * b) << "step " << step;
    EXPECT_NEAR(w.world->scene().world_pose(slider).p.z, a, 1e-12);  // children moved
    EXPECT_DOUBLE_EQ(w.world->scene().joint(w.world->scene().FindObject("/rig#0/b")).velocity,
                     -2 * 0.3);
  }
}

// Each copy's ":/" master is its own copy's: robot 1 moves its c away.
TEST_F(JointsTest, SetJointPositionMovesANonDynamicJointAndCopiesFollowTheirOwnMaster) {
  LoadedWorld w = LoadRig(R"(
function sysCall_actuation()
  if sim.getRobotIndex() == 1 and sim.getSimulationTime() == 0 then
    sim.setJointPosition(sim.getObject(':/c'), 5)
    sim.setJointPosition(sim.getObject(':/free'), -0.7)
  end
end
)");
  w.world->Step();
  EXPECT_DOUBLE_EQ(Q(*w.world, "/rig#1/free"), -0.7);
  EXPECT_DOUBLE_EQ(Q(*w.world, "/rig#0/free"), 0);
  EXPECT_NEAR(Q(*w.world, "/rig#1/c"), 5 + 0.3 * kDt, 1e-12);  // then moves on at its velocity
  EXPECT_DOUBLE_EQ(Q(*w.world, "/rig#1/b"), 0.1 - 2 * Q(*w.world, "/rig#1/c"));
  EXPECT_DOUBLE_EQ(Q(*w.world, "/rig#0/b"), 0.1 - 2 * Q(*w.world, "/rig#0/c"));
  w.world->Step();
  EXPECT_DOUBLE_EQ(Q(*w.world, "/rig#1/free"), -0.7);  // passive: it stays
}

TEST_F(JointsTest, SetJointPositionOnADependentJointIsAnErrorNamingTheMaster) {
  LoadedWorld w =
      LoadRig("function sysCall_actuation() sim.setJointPosition(sim.getObject(':/b'), 1) end\n");
  const std::string e = StepError(w);
  EXPECT_NE(e.find("follows its master ':/c'"), std::string::npos) << e;
}

TEST_F(JointsTest, SetJointPositionOnAnOdeSimulatedJointSaysToUseTheTarget) {
  LoadedWorld w = LoadOdeArm(
      "      mode: position\n",
      "function sysCall_actuation() sim.setJointPosition(sim.getObject(':/hinge'), 1) end\n");
  const std::string e = StepError(w);
  EXPECT_NE(e.find("use sim.setJointTargetPosition"), std::string::npos) << e;
}

// Under ODE a dependent joint moving a dynamic body is servoed to the formula.
TEST_F(JointsTest, OdeDependentJointTracksItsFormulaAsAPositionTarget) {
  LoadedWorld w = LoadOdeArm(
      "      mode: position\n      max_force: 100\n      master: ':/m'\n      factor: -2\n", "");
  for (int i = 0; i < 100; ++i) w.world->Step();
  const double m = Q(*w.world, "/arm#0/m"), q = Q(*w.world, "/arm#0/hinge");
  EXPECT_NEAR(m, 0.5 * 0.02 * 100, 1e-9);
  EXPECT_LT(q, -1.5);            // it moved, the master's way times -2
  EXPECT_NEAR(q, -2 * m, 0.05);  // within a step's travel of the formula
}

TEST_F(JointsTest, HashIsEqualAtOneAndTwoThreads) {
  const std::string script = R"(
function sysCall_actuation()
  sim.setJointPosition(sim.getObject(':/free'), sim.random())
end
)";
  Write("rig.yaml", kRig);
  Write("rig.lua", script);
  const std::string world =
      "simulation: {physics: kinematic, time_step: 0.05, seed: 3}\narena: {size: 20}\n"
      "models: [{model: rig.yaml, count: 24, distribute: {region: arena}}]\n";
  LoadedWorld one = Load(world, 1);
  LoadedWorld two = Load(world, 2);
  for (int i = 0; i < 30; ++i) {
    one.world->Step();
    two.world->Step();
  }
  EXPECT_EQ(one.world->StateHash(), two.world->StateHash());
  EXPECT_NE(Q(*one.world, "/rig#3/free"), 0);
}

TEST_F(JointsTest, ACycleOfDependentJointsIsALoadErrorNamingThem) {
  const std::string e =
      LoadError(std::string(kBase) + R"(    - {name: a, type: joint, master: ":/b"}
    - {name: b, type: joint, master: ":/c"}
    - {name: c, type: joint, master: ":/a"}
)");
  EXPECT_NE(e.find("rig.yaml:6:"), std::string::npos) << e;
  EXPECT_NE(e.find("cycle"), std::string::npos) << e;
  for (const char* name : {"/a'", "/b'", "/c'"}) EXPECT_NE(e.find(name), std::string::npos) << e;
}

TEST_F(JointsTest, AMasterThatIsNoJointIsALoadError) {
  const std::string e =
      LoadError(std::string(kBase) + R"(    - {name: a, type: joint, master: ":/d"}
    - {name: d, type: dummy}
)");
  EXPECT_NE(e.find("rig.yaml:6:"), std::string::npos) << e;
  EXPECT_NE(e.find("not a joint"), std::string::npos) << e;
  EXPECT_NE(LoadError("model: rig\nobjects: {name: a, type: joint, master: ':/nothere'}\n")
                .find("matches no object"),
            std::string::npos);
}

TEST_F(JointsTest, BadPitchIsAnErrorAtItsLine) {
  for (const char* pitch : {".inf", "-.inf", ".nan", "0"}) {
    const std::string e = ErrorOf("joint", std::string("  joint: screw\n  pitch: ") + pitch + "\n");
    EXPECT_NE(e.find("thing.yaml:5:"), std::string::npos) << pitch << ": " << e;
    EXPECT_NE(e.find("pitch"), std::string::npos) << e;
  }
  EXPECT_NE(ErrorOf("joint", "  joint: screw\n").find("needs 'pitch'"), std::string::npos);
  EXPECT_NE(ErrorOf("joint", "  pitch: 0.1\n").find("screw joints"), std::string::npos);
  EXPECT_NE(ErrorOf("joint", "  factor: 2\n").find("add 'master'"), std::string::npos);
}

TEST_F(JointsTest, OdeRefusesAScrewJointMovingADynamicBody) {
  std::string e = "(no error)";
  try {
    LoadedWorld w = LoadOdeArm("      joint: screw\n      pitch: 0.01\n", "");
    e = StepError(w);
  } catch (const Error& err) {
    e = err.what();
  }
  EXPECT_NE(e.find("screw joints need kinematic physics"), std::string::npos) << e;
}

}  // namespace
}  // namespace swarmsim
