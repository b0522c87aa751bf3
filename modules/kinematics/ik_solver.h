// Inverse kinematics by damped least squares (paper §2.2's IK groups).
//
// A problem has one or more *elements*: a chain (base -> tip) and the world
// pose its tip should reach, with a constraint subset (x, y, z; alpha, beta,
// gamma = rotation about the target's x, y, z). Several elements whose
// chains share joints make a branched mechanism (several tips) solved
// together. The unknowns are the union of the chains' revolute and
// prismatic joints. Each iteration:
//
//   dq = W J^T (J W J^T + lambda^2 I)^-1 e      (W: per-joint weights)
//
// with e the stacked constrained errors (position in the world, rotation in
// the target frame) and J their Jacobian, then each step is clamped to
// max_step and q to the joint limits. The solve stops when every element is
// within tolerance or after max_iterations. Conditional solving: with
// apply_only_when_solved, an unsolved problem leaves q as it was.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "framework/math.h"
#include "modules/kinematics/chain.h"

namespace swarmsim::kinematics {

enum IkConstraint : uint8_t {
  kX = 1,
  kY = 2,
  kZ = 4,
  kAlpha = 8,
  kBeta = 16,
  kGamma = 32,
  kPosition = kX | kY | kZ,
  kOrientation = kAlpha | kBeta | kGamma,
  kPose = kPosition | kOrientation,
};

struct IkSettings {
  double damping = 1e-3;  // lambda
  int max_iterations = 30;
  double position_tolerance = 1e-5;     // m
  double orientation_tolerance = 1e-4;  // rad
  double max_step = 0.4;                // rad or m per iteration and joint
  bool apply_only_when_solved = true;   // conditional solving
};

struct IkResult {
  bool solved = false;
  int iterations = 0;
  double position_error = 0;     // m, worst element
  double orientation_error = 0;  // rad, worst element
};

inline constexpr int kMaxIkDof = 32;
inline constexpr int kMaxIkElements = 4;

class IkProblem {
 public:
  // Returns the element index.
  int AddElement(Chain chain, const Pose& X_WTarget, uint8_t constraints = kPose);
  // An element whose target hangs below the same base through joints (a
  // closed chain): the target moves with q too; its chain's joints are
  // unknowns as well. Both chains start at the same base.
  int AddClosedElement(Chain tip_chain, Chain target_chain, uint8_t constraints = kPose);
  void set_target(int element, const Pose& X_WTarget) {
    elements_.at(element).X_WTarget = X_WTarget;
  }
  // Moving bases: the world pose of an element's base (both its chains).
  void set_base_pose(int element, const Pose& X_WBase);
  const Chain& chain(int element) const { return elements_.at(element).chain; }

  // The unknowns: scene slots of the joints, in column order.
  int dof() const { return static_cast<int>(slots_.size()); }
  std::span<const uint32_t> joint_slots() const { return slots_; }
  void set_weight(int column, double weight) { weights_.at(column) = weight; }

  // Positions of the unknowns in the scene / written back to it.
  std::vector<double> ReadPositions(const Scene& scene) const;
  void WritePositions(std::span<const double> q, Scene* scene) const;

  // Solves from q (size dof()), updating it (see apply_only_when_solved).
  IkResult Solve(const IkSettings& settings, std::vector<double>* q) const;

 private:
  struct Element {
    Chain chain;
    Pose X_WTarget;
    uint8_t constraints = kPose;
    std::vector<int> columns;  // per chain joint
    bool closed = false;       // target_chain gives the target
    Chain target_chain;
    std::vector<int> target_columns;  // per target chain joint
  };
  int AddColumn(const ChainJoint& joint);
  std::vector<Element> elements_;
  std::vector<uint32_t> slots_;
  std::vector<double> weights_, min_, max_;
  std::vector<uint8_t> prismatic_;
};

}  // namespace swarmsim::kinematics
