// Published robot descriptions (../shared/urdf-corpus: 15 URDF files of 8
// robots from example-robot-data, as their authors wrote them: massless
// frames on fixed joints, tiny, singular or unbalanced inertias, mirrored
// meshes, mimic and transmission joints) load; each hangs from its fixed
// base under ODE for 2 s without exploding; and the imported links sit
// where the URDF's joints put them, composed here from the XML
// independently of the importer, at three joint configurations.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "framework/world.h"
#include "swarm/loader/world_loader.h"
#include "tests/shared_urdf.h"
#include "tests/swarm/loader/urdf_xml_kinematics.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::ForwardKinematics;
using testing::ReadJoints;
using testing::XmlJoint;

// Every URDF of the corpus: robot folder (its package path), file below it.
struct CorpusFile {
  const char* robot;
  const char* urdf;
};
constexpr CorpusFile kFiles[] = {
    {"bolt", "example-robot-data/robots/bolt_description/robots/bolt.urdf"},
    {"double_pendulum",
     "example-robot-data/robots/double_pendulum_description/urdf/double_pendulum.urdf"},
    {"double_pendulum",
     "example-robot-data/robots/double_pendulum_description/urdf/double_pendulum_continuous.urdf"},
    {"double_pendulum",
     "example-robot-data/robots/double_pendulum_description/urdf/double_pendulum_simple.urdf"},
    {"hyq", "example-robot-data/robots/hyq_description/robots/hyq_no_sensors.urdf"},
    {"icub", "example-robot-data/robots/icub_description/robots/icub.urdf"},
    {"icub", "example-robot-data/robots/icub_description/robots/icub_reduced.urdf"},
    {"iris", "example-robot-data/robots/iris_description/robots/iris.urdf"},
    {"iris", "example-robot-data/robots/iris_description/robots/iris_simple.urdf"},
    {"kinova", "example-robot-data/robots/kinova_description/robots/kinova.urdf"},
    {"solo", "example-robot-data/robots/solo_description/robots/solo.urdf"},
    {"solo", "example-robot-data/robots/solo_description/robots/solo12.urdf"},
    {"tiago", "example-robot-data/robots/tiago_description/robots/tiago.urdf"},
    {"tiago", "example-robot-data/robots/tiago_description/robots/tiago_dual.urdf"},
    {"tiago", "example-robot-data/robots/tiago_description/robots/tiago_no_hand.urdf"},
};

// --- The URDF's kinematics, read from the XML here ------------------------------------

bool Moves(const XmlJoint& j) {
  return j.type == "revolute" || j.type == "continuous" || j.type == "prismatic";
}

// Joint values of configuration `k` (0: all zero), mimic joints following
// their masters.
std::map<std::string, double> Configuration(const std::vector<XmlJoint>& joints, int k) {
  std::map<std::string, double> q;
  int i = 0;
  for (const XmlJoint& j : joints) {
    if (!Moves(j)) continue;
    const double wave = k == 0 ? 0 : std::sin(1.3 * k + 0.7 * i++);
    q[j.name] = j.type == "prismatic" ? 0.05 * wave : 1.2 * wave;
  }
  for (const XmlJoint& j : joints)
    if (Moves(j) && !j.mimic.empty() && q.contains(j.mimic))
      q[j.name] = j.multiplier * q[j.mimic] + j.offset;
  return q;
}

class UrdfCorpusTest : public testing::WorldDirTest {
 protected:
  // Steps of 10 ms, the examples' (and most users') step. (Before the ODE
  // accuracy defaults the two iCub files, light hands and wrists under
  // stiff servos, diverged after 1.1-1.4 s at 10 ms.)
  static constexpr double kStep = 0.01;
  LoadedWorld LoadFile(const std::string& dir, const CorpusFile& f, const std::string& physics) {
    return Load("simulation: {physics: " + physics + ", time_step: " + std::to_string(kStep) +
                "}\npackage_path: [" + dir + "/" + f.robot + "]\nmodels:\n  - model: " + dir + "/" +
                f.robot + "/" + f.urdf + "\n    position: [0, 0, 1]\n");
  }
  // The object of link or joint `name` of the first robot (the root link is
  // the robot's root); null if there is none of that name and kind.
  // (Names with spaces, '/', '[' or ']' have '_' instead: worlds/README.md.)
  static ObjectId Find(const Scene& scene, std::string name, bool joint) {
    for (char& c : name)
      if (c == '/' || c == '[' || c == ']' || c == ' ') c = '_';
    const ObjectId root = scene.instances()[0].root;
    ObjectId id = scene.FindObject("./" + name, root);
    if (!id.IsNull() && (scene.type(id) == ObjectType::kJoint) != joint) return ObjectId{};
    return id;
  }
};

TEST_F(UrdfCorpusTest, EveryFileLoadsAndHangsUnderOdeForTwoSeconds) {
  NEED_CORPUS(dir);
  for (const CorpusFile& f : kFiles) {
    SCOPED_TRACE(f.urdf);
    LoadedWorld w;
    ASSERT_NO_THROW(w = LoadFile(dir, f, "ode"));
    // One warning at most of each kind (repaired inertias, default masses).
    int repaired = 0, defaults = 0;
    for (const std::string& warning : w.warnings) {
      repaired += warning.find("balanceinertia") != std::string::npos;
      defaults += warning.find("default mass") != std::string::npos;
    }
    EXPECT_LE(repaired, 1);
    EXPECT_LE(defaults, 1);
    World& world = *w.world;
    Scene& scene = world.scene();
    std::vector<Vec3> start(scene.slot_count());
    double mass = 0;
    for (uint32_t s = 0; s < scene.slot_count(); ++s) {
      start[s] = scene.world_pose_at(s).p;
      if (scene.alive_at(s) && scene.type_at(s) == ObjectType::kShape &&
          scene.shape(scene.IdAt(s)).dynamic)
        mass += scene.shape(scene.IdAt(s)).mass;
    }
    // (iris_simple's links are all fixed to its base: nothing moves.)
    world.Start();
    double most_kinetic = 0, farthest = 0;
    bool finite = true;
    for (int k = 0; k * kStep < 2; ++k) {
      ASSERT_NO_THROW(world.Step()) << "at " << k * kStep << " s";
      double kinetic = 0;
      for (uint32_t s = 0; s < scene.slot_count(); ++s) {
        if (!scene.alive_at(s)) continue;
        const Pose& X = scene.world_pose_at(s);
        finite = finite && std::isfinite(X.p.x + X.p.y + X.p.z + X.q.w + X.q.x + X.q.y + X.q.z);
        farthest = std::max(farthest, (X.p - start[s]).Norm());
        if (scene.type_at(s) == ObjectType::kShape && scene.shape(scene.IdAt(s)).dynamic)
          kinetic +=
              0.5 * scene.shape(scene.IdAt(s)).mass * scene.linear_velocity_at(s).SquaredNorm();
      }
      most_kinetic = std::max(most_kinetic, kinetic);
    }
    EXPECT_TRUE(finite);
    // Hung at 1 m from a fixed base: no link goes farther than the robot's
    // reach from where it started, and the kinetic energy stays below what
    // the whole mass would gain falling 2 m (an explosion gains far more).
    EXPECT_LT(farthest, 2.5);
    EXPECT_LE(most_kinetic, mass * 9.81 * 2);
  }
}

// The published double pendulum's revolute joints say lower = upper = 0:
// held there (a warning says so and how to free them); with the models
// entry's joints: {mode: passive, limits: false} it swings under gravity
// (the base tilted 20 degrees about the joints' x axis: upright, the links
// would balance for seconds before falling).
TEST_F(UrdfCorpusTest, TheDoublePendulumHeldByItsLimitsSwingsOnceFreed) {
  NEED_CORPUS(dir);
  const std::string robot = dir + "/double_pendulum";
  const std::string urdf =
      robot + "/example-robot-data/robots/double_pendulum_description/urdf/double_pendulum.urdf";
  const auto world = [&](const std::string& joints) {
    return "simulation: {physics: ode, time_step: 0.01}\npackage_path: [" + robot +
           "]\nmodels:\n  - model: " + urdf +
           "\n    position: [0, 0, 1]\n    orientation_deg: [20, 0, 0]\n" + joints;
  };
  const auto swing = [&](LoadedWorld* w) {
    w->world->Start();
    const ObjectId joint = Find(w->world->scene(), "joint1", true);
    EXPECT_FALSE(joint.IsNull());
    double most = 0;
    for (int k = 0; k < 150; ++k) {
      w->world->Step();
      most = std::max(most, std::abs(w->world->scene().joint(joint).position));
    }
    return most;
  };
  LoadedWorld held = Load(world(""));
  bool warned = false;
  for (const std::string& warning : held.warnings)
    warned = warned || (warning.find("2 joints have <limit lower> equal to upper (joint1, "
                                     "joint2): held there") != std::string::npos &&
                        warning.find("joints: {limits: false}") != std::string::npos);
  EXPECT_TRUE(warned) << "no warning of the held joints";
  EXPECT_LT(swing(&held), 0.05);
  LoadedWorld freed = Load(world("    joints: {mode: passive, limits: false}\n"));
  EXPECT_GT(swing(&freed), 0.3) << "a pendulum started off its rest position swings";
}

TEST_F(UrdfCorpusTest, LinksSitWhereTheXmlJointsPutThemAtThreeConfigurations) {
  NEED_CORPUS(dir);
  for (const CorpusFile& f : kFiles) {
    SCOPED_TRACE(f.urdf);
    std::vector<std::string> links;
    const std::vector<XmlJoint> joints = ReadJoints(dir + "/" + f.robot + "/" + f.urdf, &links);
    std::set<std::string> children;
    for (const XmlJoint& j : joints) children.insert(j.child);
    std::string root;
    for (const std::string& l : links)
      if (!children.contains(l)) root = l;
    LoadedWorld w = LoadFile(dir, f, "kinematic");
    Scene& scene = w.world->scene();
    const ObjectId robot = scene.instances()[0].root;
    for (int k = 1; k <= 3; ++k) {
      const std::map<std::string, double> q = Configuration(joints, k);
      for (const auto& [name, value] : q) {
        const ObjectId joint = Find(scene, name, true);
        ASSERT_FALSE(joint.IsNull()) << name;
        scene.mutable_joint(joint).position = value;
      }
      scene.UpdateWorldPoses();
      const std::map<std::string, Pose> expected = ForwardKinematics(joints, q);
      ASSERT_EQ(expected.size(), links.size());
      const Pose X_WR = scene.world_pose(robot);
      for (const auto& [link, X_RL] : expected) {
        const ObjectId id = link == root ? robot : Find(scene, link, false);
        ASSERT_FALSE(id.IsNull()) << link;
        const Pose X = X_WR * X_RL;
        const Pose got = scene.world_pose(id);
        EXPECT_NEAR((got.p - X.p).Norm(), 0, 1e-9) << link << " at configuration " << k;
        const double dot = got.q.w * X.q.w + got.q.x * X.q.x + got.q.y * X.q.y + got.q.z * X.q.z;
        EXPECT_NEAR(std::abs(dot), 1, 1e-9) << link << " at configuration " << k;
      }
    }
  }
}

}  // namespace
}  // namespace swarmsim
