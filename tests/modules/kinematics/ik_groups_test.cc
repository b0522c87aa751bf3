// IK groups as calculation objects: solved in the actuate phase, copied and
// removed with their model, the same whatever the thread count; several
// tips and closed chains; frozen joints, spherical, screw and dependent
// joints as unknowns.
#include "modules/kinematics/ik_groups.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"

namespace swarmsim {
namespace {

const ModuleRegistry& Registry() {
  static ModuleRegistry* registry = [] {
    auto* r = new ModuleRegistry;
    RegisterBuiltinModules(r);
    return r;
  }();
  return *registry;
}

std::unique_ptr<World> MakeWorld(int threads) {
  WorldSettings settings;
  settings.physics = "kinematic";
  settings.threads = threads;
  settings.time_step = 0.05;
  auto world = std::make_unique<World>(settings, Registry());
  world->set_log_sink([](std::string_view) {});
  return world;
}

// A planar 2-link arm (links 0.5 m and 0.4 m, joints about z) as a model
// rooted at a dummy, with a target dummy under the root.
struct Arm {
  ObjectId root, j1, j2, tip, target;
};
Arm AddArm(Scene* scene, const Pose& X_WRoot) {
  Arm a;
  JointData joint;
  joint.settings.Edit().mode = JointMode::kPassive;
  a.root = scene->AddDummy("arm", {}, X_WRoot);
  a.j1 = scene->AddJoint("j1", a.root, {}, joint);
  joint.position = 0.3;  // away from the straight singularity
  a.j2 = scene->AddJoint("j2", a.j1, {{0.5, 0, 0}, {}}, joint);
  a.tip = scene->AddDummy("tip", a.j2, {{0.4, 0, 0}, {}});
  a.target = scene->AddDummy("target", a.root, {{0.6, 0.3, 0}, {}});
  scene->MakeModelInstance(a.root, "arm", "arm#" + std::to_string(scene->instances().size()));
  return a;
}

IkGroups* Ik(World* world) { return &kinematics::IkGroupsOf(world); }

IkGroupSpec ArmGroup(const Arm& a) {
  IkGroupSpec spec;
  spec.name = "reach";
  spec.tips.push_back({a.tip, a.target, {}, kIkX | kIkY});
  spec.max_iterations = 50;
  spec.position_tolerance = 1e-6;
  return spec;
}

// A group "reach" of one tip solved to `tolerance` (m and rad) in up to 100 iterations.
IkGroupSpec ReachGroup(ObjectId tip, ObjectId target, uint8_t constraints, double tolerance) {
  IkGroupSpec spec;
  spec.name = "reach";
  spec.tips.push_back({tip, target, {}, constraints});
  spec.max_iterations = 100;
  spec.position_tolerance = tolerance;
  spec.orientation_tolerance = tolerance;
  return spec;
}

double Distance(const Scene& scene, ObjectId a, ObjectId b) {
  return (scene.world_pose(a).p - scene.world_pose(b).p).Norm();
}

TEST(IkGroupsTest, SolvedInTheActuatePhase) {
  auto world = MakeWorld(1);
  const Arm arm = AddArm(&world->scene(), {});
  IkGroups* ik = Ik(world.get());
  const int h = ik->AddGroup(world->scene(), ArmGroup(arm));
  world->Start();
  world->Step();
  EXPECT_EQ(ik->last_status(h), IkStatus::kSolved);
  EXPECT_LT(Distance(world->scene(), arm.tip, arm.target), 1e-5);
}

TEST(IkGroupsTest, DuplicatedModelsGroupSolvesForTheCopyAndIsRemovedWithIt) {
  auto world = MakeWorld(1);
  Scene& scene = world->scene();
  const Arm arm = AddArm(&scene, {});
  IkGroups* ik = Ik(world.get());
  ik->AddGroup(scene, ArmGroup(arm));
  const ObjectId copy = scene.DuplicateSubtree(arm.root, {});
  scene.SetWorldPose(copy, {{3, 0, 0}, Quat::FromYaw(1.0)});
  const int copy_instance = scene.instance_of(copy);
  ASSERT_EQ(ik->live_group_count(), 2);
  const int copy_group = ik->FindGroup("reach", copy_instance);
  ASSERT_NE(copy_group, 0);
  // The copy refers to its own tip and target, not the original's.
  const ObjectId copy_tip = scene.FindObject("./tip", copy);
  const ObjectId copy_target = scene.FindObject("./target", copy);
  EXPECT_EQ(ik->spec(copy_group).tips[0].tip, copy_tip);
  EXPECT_EQ(ik->spec(copy_group).tips[0].target, copy_target);
  scene.SetLocalPose(copy_target, {{0.2, -0.5, 0}, {}});
  world->Start();
  world->Step();
  EXPECT_LT(Distance(scene, arm.tip, arm.target), 1e-5);
  EXPECT_LT(Distance(scene, copy_tip, copy_target), 1e-5);
  // Deleting the copy deletes its group; the original's still works.
  scene.RemoveSubtree(copy);
  EXPECT_EQ(ik->live_group_count(), 1);
  EXPECT_FALSE(ik->IsLive(copy_group));
  scene.SetLocalPose(arm.target, {{0.1, 0.7, 0}, {}});
  world->Step();
  EXPECT_LT(Distance(scene, arm.tip, arm.target), 1e-5);
}

// Copies and removals by scripts at run time (sim.copyModel,
// sim.removeModel): the IK group follows through the same SceneListener.
TEST(IkGroupsTest, RobotsCopiedAndRemovedByScriptsTakeTheirGroupsAlong) {
  auto world = MakeWorld(1);
  Scene& scene = world->scene();
  const Arm arm = AddArm(&scene, {});
  IkGroups* ik = Ik(world.get());
  ik->AddGroup(scene, ArmGroup(arm));
  scene.AttachScript(arm.root, std::make_shared<const ScriptSource>(ScriptSource{"arm.lua", R"(
    local step = 0
    function sysCall_actuation()
      step = step + 1
      if sim.getRobotIndex() ~= 0 then return end
      if step == 1 then sim.copyModel(sim.getObject(':'), {3, 0, 1}) end
      if step == 3 then sim.removeModel(sim.getObject('/arm#1')) end
    end
  )"}));
  world->Step();
  ASSERT_EQ(world->robot_count(), 2);
  ASSERT_EQ(ik->live_group_count(), 2);
  const ObjectId copy = scene.instance(1).root;
  const int copy_group = ik->FindGroup("reach", 1);
  ASSERT_NE(copy_group, 0);
  EXPECT_EQ(ik->spec(copy_group).tips[0].tip, scene.FindObject("./tip", copy));
  world->Step();
  EXPECT_LT(Distance(scene, scene.FindObject("./tip", copy), scene.FindObject("./target", copy)),
            1e-5);
  world->Step();  // the removal
  EXPECT_EQ(ik->live_group_count(), 1);
  EXPECT_FALSE(ik->IsLive(copy_group));
  world->Step();
  EXPECT_LT(Distance(scene, arm.tip, arm.target), 1e-5);
}

TEST(IkGroupsTest, ParallelSolveEqualsSerial) {
  std::vector<double> positions[2];
  for (int threads : {1, 2}) {
    auto world = MakeWorld(threads);
    Scene& scene = world->scene();
    const Arm arm = AddArm(&scene, {});
    Ik(world.get())->AddGroup(scene, ArmGroup(arm));
    std::vector<ObjectId> targets;
    for (int i = 1; i < 64; ++i) {
      const ObjectId copy = scene.DuplicateSubtree(arm.root, {});
      scene.SetWorldPose(copy, {{2.0 * i, 0, 0}, {}});
      scene.SetLocalPose(scene.FindObject("./target", copy),
                         {{0.3 + 0.005 * i, 0.2 + 0.007 * i, 0}, {}});
    }
    world->Start();
    for (int s = 0; s < 3; ++s) world->Step();
    for (const JointData& j : scene.joints()) positions[threads - 1].push_back(j.position);
  }
  ASSERT_EQ(positions[0].size(), 128u);
  EXPECT_EQ(positions[0], positions[1]);  // bit for bit
}

TEST(IkGroupsTest, SeveralTipsAndAClosedChain) {
  auto world = MakeWorld(1);
  Scene& scene = world->scene();
  // Two arms on one base: arm A's tip must meet a dummy on arm B (a closed
  // chain: both arms' joints move), and arm B's tip a fixed target.
  JointData joint;
  joint.settings.Edit().mode = JointMode::kPassive;
  const ObjectId root = scene.AddDummy("base", {}, {});
  const ObjectId a1 = scene.AddJoint("a1", root, {}, joint);
  joint.position = 0.4;
  const ObjectId a2 = scene.AddJoint("a2", a1, {{0.5, 0, 0}, {}}, joint);
  const ObjectId tip_a = scene.AddDummy("tipA", a2, {{0.5, 0, 0}, {}});
  joint.position = -0.4;
  const ObjectId b1 = scene.AddJoint("b1", root, {{0, 0.6, 0}, {}}, joint);
  const ObjectId b2 = scene.AddJoint("b2", b1, {{0.5, 0, 0}, {}}, joint);
  const ObjectId tip_b = scene.AddDummy("tipB", b2, {{0.5, 0, 0}, {}});
  const ObjectId mid_b = scene.AddDummy("midB", b1, {{0.5, 0, 0}, {}});  // on arm B
  const ObjectId fixed = scene.AddDummy("fixed", root, {{0.9, 0.8, 0}, {}});
  scene.MakeModelInstance(root, "pair", "pair#0");
  IkGroupSpec spec;
  spec.name = "pair";
  spec.tips.push_back({tip_a, mid_b, {}, kIkX | kIkY});
  spec.tips.push_back({tip_b, fixed, {}, kIkX | kIkY});
  spec.max_iterations = 100;
  spec.position_tolerance = 1e-6;
  IkGroups* ik = Ik(world.get());
  const int h = ik->AddGroup(scene, spec);
  (void)b2;
  EXPECT_EQ(ik->Handle(h, &scene), IkStatus::kSolved);
  EXPECT_LT(Distance(scene, tip_a, mid_b), 1e-5);
  EXPECT_LT(Distance(scene, tip_b, fixed), 1e-5);
}

TEST(IkGroupsTest, ConditionalSolvingLeavesJointsOfAnUnreachableTarget) {
  auto world = MakeWorld(1);
  Scene& scene = world->scene();
  const Arm arm = AddArm(&scene, {});
  scene.SetLocalPose(arm.target, {{5, 0, 0}, {}});  // beyond reach (0.9 m)
  IkGroupSpec spec = ArmGroup(arm);
  spec.conditional = true;
  IkGroups* ik = Ik(world.get());
  const int h = ik->AddGroup(scene, spec);
  EXPECT_EQ(ik->Handle(h, &scene), IkStatus::kFailed);
  EXPECT_EQ(scene.joint(arm.j1).position, 0.0);
  EXPECT_EQ(scene.joint(arm.j2).position, 0.3);
}

// A three-link planar arm: j1 at the root, j2 0.5 m along, j3 0.4 m
// further, the tip 0.3 m beyond j3; the target under the root.
struct Arm3 {
  ObjectId root, j1, j2, j3, tip, target;
};
Arm3 AddArm3(Scene* scene, const JointData& second) {
  Arm3 a;
  JointData joint;
  joint.settings.Edit().mode = JointMode::kPassive;
  a.root = scene->AddDummy("arm", {}, {});
  a.j1 = scene->AddJoint("j1", a.root, {}, joint);
  a.j2 = scene->AddJoint("j2", a.j1, {{0.5, 0, 0}, {}}, second);
  joint.position = 0.3;
  a.j3 = scene->AddJoint("j3", a.j2, {{0.4, 0, 0}, {}}, joint);
  a.tip = scene->AddDummy("tip", a.j3, {{0.3, 0, 0}, {}});
  a.target = scene->AddDummy("target", a.root, {{0.6, 0.5, 0}, {}});
  scene->MakeModelInstance(a.root, "arm", "arm#0");
  return a;
}

// A joint in IK mode `frozen` keeps its value while the others reach the
// target; the same arm with it active moves it.
TEST(IkGroupsTest, FrozenJointKeepsItsValueWhileTheOthersReach) {
  for (bool frozen : {true, false}) {
    auto world = MakeWorld(1);
    Scene& scene = world->scene();
    JointData second;
    second.settings.Edit().mode = JointMode::kPassive;
    second.position = 0.3;
    second.ik_frozen = frozen;
    const Arm3 arm = AddArm3(&scene, second);
    const IkGroupSpec spec = ReachGroup(arm.tip, arm.target, kIkX | kIkY, 1e-6);
    IkGroups* ik = Ik(world.get());
    const int h = ik->AddGroup(scene, spec);
    world->Start();
    world->Step();
    EXPECT_EQ(ik->last_status(h), IkStatus::kSolved) << frozen;
    EXPECT_LT(Distance(scene, arm.tip, arm.target), 1e-5) << frozen;
    if (frozen)
      EXPECT_EQ(scene.joint(arm.j2).position, 0.3);
    else
      EXPECT_GT(std::abs(scene.joint(arm.j2).position - 0.3), 1e-3);
  }
}

// A dependent joint (q2 = 0.1 - q1) is no unknown of its own: the solve
// moves it with its master, so the tip is on the target after the step's
// dependent-joint pass too.
TEST(IkGroupsTest, DependentJointMovesWithItsMasterDuringTheSolve) {
  auto world = MakeWorld(1);
  Scene& scene = world->scene();
  JointData second;
  second.settings.Edit().mode = JointMode::kPassive;
  auto depends = std::make_shared<JointDependency>();
  depends->master = ":/j1";
  depends->factor = -1;
  depends->offset = 0.1;
  second.settings.Edit().depends = depends;
  second.position = 0.1;
  const Arm3 arm = AddArm3(&scene, second);
  // Reachable with q1 = 0.5, q3 = 0.9 (q2 = -0.4): link 2 always points
  // 0.1 rad off the root's x axis.
  const double q1 = 0.5, q3 = 0.9;
  const Vec3 target{0.5 * std::cos(q1) + 0.4 * std::cos(0.1) + 0.3 * std::cos(0.1 + q3),
                    0.5 * std::sin(q1) + 0.4 * std::sin(0.1) + 0.3 * std::sin(0.1 + q3), 0};
  scene.SetLocalPose(arm.target, {target, {}});
  const IkGroupSpec spec = ReachGroup(arm.tip, arm.target, kIkX | kIkY, 1e-7);
  IkGroups* ik = Ik(world.get());
  const int h = ik->AddGroup(scene, spec);
  world->Start();
  world->Step();
  EXPECT_EQ(ik->last_status(h), IkStatus::kSolved);
  EXPECT_NEAR(scene.joint(arm.j2).position, 0.1 - scene.joint(arm.j1).position, 1e-12);
  EXPECT_LT(Distance(scene, arm.tip, arm.target), 1e-6);
}

// A screw joint (pitch 0.1 m/rad) is an unknown: the tip 0.2 m off its
// axis reaches a point that needs both its turn and its travel.
TEST(IkGroupsTest, ScrewJointTurnsAndTravelsToTheTarget) {
  auto world = MakeWorld(1);
  Scene& scene = world->scene();
  JointData screw;
  screw.settings.Edit().type = JointType::kScrew;
  screw.settings.Edit().mode = JointMode::kPassive;
  screw.settings.Edit().pitch = 0.1;
  const ObjectId root = scene.AddDummy("screw", {}, {});
  const ObjectId joint = scene.AddJoint("j", root, {}, screw);
  const ObjectId tip = scene.AddDummy("tip", joint, {{0.2, 0, 0}, {}});
  const ObjectId target =
      scene.AddDummy("target", root, {{0.2 * std::cos(1.0), 0.2 * std::sin(1.0), 0.1}, {}});
  scene.MakeModelInstance(root, "screw", "screw#0");
  const IkGroupSpec spec = ReachGroup(tip, target, kIkPosition, 1e-7);
  IkGroups* ik = Ik(world.get());
  EXPECT_EQ(ik->Handle(ik->AddGroup(scene, spec), &scene), IkStatus::kSolved);
  EXPECT_NEAR(scene.joint(joint).position, 1.0, 1e-6);
  EXPECT_LT(Distance(scene, tip, target), 1e-6);
}

// A revolute shoulder and a spherical wrist reach a pose whose orientation
// tilts out of the shoulder's plane; the same arm with a revolute wrist
// (same place, same axis z) cannot.
TEST(IkGroupsTest, SphericalJointOrientsWhereARevoluteChainCannot) {
  const Quat tilt = Quat::FromAxisAngle({0, 1, 0}, -0.6) * Quat::FromAxisAngle({1, 0, 0}, 0.3);
  const Quat q_WT = Quat::FromYaw(0.4) * tilt;
  const Pose X_WTarget{Quat::FromYaw(0.4).Rotate({0.5, 0, 0}) + q_WT.Rotate({0.3, 0, 0}), q_WT};
  for (JointType wrist : {JointType::kSpherical, JointType::kRevolute}) {
    auto world = MakeWorld(1);
    Scene& scene = world->scene();
    JointData joint;
    joint.settings.Edit().mode = JointMode::kPassive;
    const ObjectId root = scene.AddDummy("arm", {}, {});
    const ObjectId shoulder = scene.AddJoint("shoulder", root, {}, joint);
    joint.settings.Edit().type = wrist;
    const ObjectId j2 = scene.AddJoint("wrist", shoulder, {{0.5, 0, 0}, {}}, joint);
    const ObjectId tip = scene.AddDummy("tip", j2, {{0.3, 0, 0}, {}});
    const ObjectId target = scene.AddDummy("target", root, X_WTarget);
    scene.MakeModelInstance(root, "arm", "arm#0");
    const IkGroupSpec spec = ReachGroup(tip, target, kIkPose, 1e-6);
    IkGroups* ik = Ik(world.get());
    const IkStatus status = ik->Handle(ik->AddGroup(scene, spec), &scene);
    const Quat q_error = scene.world_pose(tip).q.Conjugate() * X_WTarget.q;
    const double angle = 2 * std::acos(std::min(1.0, std::abs(q_error.w)));
    if (wrist == JointType::kSpherical) {
      EXPECT_EQ(status, IkStatus::kSolved);
      EXPECT_LT(Distance(scene, tip, target), 1e-5);
      EXPECT_LT(angle, 1e-5);
      EXPECT_NEAR(scene.joint(shoulder).position, 0.4, 1e-5);
    } else {
      EXPECT_EQ(status, IkStatus::kFailed);
      EXPECT_GT(angle, 0.3);
    }
  }
}

// A spherical joint has no target position: a group in targets mode
// cannot take one.
TEST(IkGroupsTest, SphericalJointInATargetsModeGroupIsAnError) {
  auto world = MakeWorld(1);
  Scene& scene = world->scene();
  JointData joint;
  joint.settings.Edit().type = JointType::kSpherical;
  const ObjectId root = scene.AddDummy("arm", {}, {});
  const ObjectId ball = scene.AddJoint("ball", root, {}, joint);
  const ObjectId tip = scene.AddDummy("tip", ball, {{0.3, 0, 0}, {}});
  const ObjectId target = scene.AddDummy("target", root, {{0, 0.3, 0}, {}});
  scene.MakeModelInstance(root, "arm", "arm#0");
  IkGroupSpec spec;
  spec.name = "reach";
  spec.mode = IkMode::kJointTargets;
  spec.tips.push_back({tip, target, {}, kIkPosition});
  try {
    Ik(world.get())->AddGroup(scene, spec);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("spherical joint '"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("direct mode"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace swarmsim
