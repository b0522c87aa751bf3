// IK groups as calculation objects (paper §2.2): the kinematics module's
// public header. The solver (Eigen, damped least squares) is this folder's
// own (ik_groups.cc, ik_solver.cc), registered as the calculation module
// "ik" with its Lua area (lua_api_ik.cc); the loader adds a model's groups
// through this interface (IkGroupsOf).
//
// A group has one or more tip/target pairs, each solved for a constraint
// subset (x, y, z; alpha, beta, gamma about the target's axes). The joints
// are the revolute, prismatic, screw and spherical joints between each tip
// and its base (by default the tip's model root), but those in IK mode
// `frozen` (JointData::ik_frozen) keep their values, and dependent joints
// follow their masters. A target that hangs below the base through joints
// makes a closed chain: those joints are unknowns too. A group may keep
// chosen links at least a distance from an obstacle (IkAvoidSpec; the
// collision module measures it).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/calculation_module.h"
#include "framework/handle.h"
#include "framework/registry.h"

namespace swarmsim {

inline constexpr const char* kIkModuleName = "ik";

enum class IkMode : uint8_t {
  kDirect,        // joint positions are set (kinematic motion)
  kJointTargets,  // joint target positions are set; the dynamics backend tracks them
};

// Constraint bits (same values as kinematics::IkConstraint).
enum IkConstraintBits : uint8_t {
  kIkX = 1,
  kIkY = 2,
  kIkZ = 4,
  kIkAlpha = 8,
  kIkBeta = 16,
  kIkGamma = 32,
  kIkPosition = 7,
  kIkPose = 63,
};

struct IkTipSpec {
  ObjectId tip, target;
  ObjectId base;  // null: the tip's model root (the world for scene objects)
  uint8_t constraints = kIkPosition;
};

// Obstacle avoidance: each link (a rigid body: the object and what hangs
// below it without crossing a joint) stays at least `distance` from
// `obstacle`.
struct IkAvoidSpec {
  std::vector<ObjectId> links;
  // A path resolved from the group's model root as distance objects
  // resolve theirs (a collection, or an object and its subtree), or
  // "environment".
  std::string obstacle;
  double distance = 0.05;  // m, > 0
  std::string where;       // "file:line:column" of `obstacle`, for errors
};

struct IkGroupSpec {
  std::string name;
  std::vector<IkTipSpec> tips;
  IkMode mode = IkMode::kDirect;
  double damping = 0.01;
  int max_iterations = 20;
  double position_tolerance = 1e-4;     // m
  double orientation_tolerance = 1e-3;  // rad
  double max_step = 0.2;                // rad or m per iteration and joint
  bool conditional = false;  // apply only when solved, else leave the joints as they were
  bool automatic = true;  // solved each step in the actuate phase (else only by sim.handleIkGroup)
  std::vector<std::pair<ObjectId, double>> weights;  // per joint, default 1
  std::vector<IkAvoidSpec> avoid;
};

// V-REP's sim.ikresult_* values.
enum class IkStatus : uint8_t { kNotPerformed = 0, kSolved = 1, kFailed = 2 };

class IkGroups : public CalculationModule {
 public:
  // Adds a group; returns its handle (> 0, never reused). Throws
  // swarmsim::Error if an object is invalid or a tip has no joints.
  // Obstacles are resolved by CheckReferences (once the world's objects
  // exist) or at the first solve.
  virtual int AddGroup(const Scene& scene, IkGroupSpec spec) = 0;
  // Resolves every group's obstacles; throws swarmsim::Error naming the
  // entry's file:line:column when a path matches nothing (the loader calls
  // it through World::CheckModuleReferences).
  void CheckReferences(const Scene& scene) override = 0;
  // Handle of the live group named `name` of robot `instance` (-1: scene
  // groups), or 0.
  virtual int FindGroup(std::string_view name, int instance) const = 0;
  virtual bool IsLive(int handle) const = 0;
  virtual int instance_of(int handle) const = 0;  // throws for a stale handle
  virtual const IkGroupSpec& spec(int handle) const = 0;
  // Solves one group now and applies the result. Direct mode refreshes the
  // world poses of the group's robot.
  virtual IkStatus Handle(int handle, Scene* scene) = 0;
  // Status of the group's last solve.
  virtual IkStatus last_status(int handle) const = 0;
  virtual int live_group_count() const = 0;
};

namespace kinematics {

// The world's IK groups, made on first use (World::module).
IkGroups& IkGroupsOf(World* world);
// Null if the world has none yet.
IkGroups* FindIkGroups(const World& world);

// Registers the "ik" calculation module and its Lua area (modules/builtin.cc).
void Register(ModuleRegistry* registry);

}  // namespace kinematics
}  // namespace swarmsim
