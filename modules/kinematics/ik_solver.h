// Inverse kinematics by damped least squares (paper §2.2's IK groups).
//
// A problem has one or more *elements*: a chain (base -> tip) and the world
// pose its tip should reach, with a constraint subset (x, y, z; alpha, beta,
// gamma = rotation about the target's x, y, z). Several elements whose
// chains share joints make a branched mechanism (several tips) solved
// together. The unknowns (columns) are the chains' joints: one for a
// revolute, prismatic or screw joint, three for a spherical joint (a
// rotation vector about its frame's x, y, z, applied to its `ball`). Each
// iteration:
//
//   dq = W J^T (J W J^T + lambda^2 I)^-1 e      (W: per-column weights)
//
// with e the stacked constrained errors (position in the world, rotation in
// the target frame) and J their Jacobian, then each step is clamped to
// max_step and q to the joint limits. Frozen columns (weight 0) keep their
// value; a dependent column (q = offset + factor * q_master) folds its
// Jacobian column into its master's and follows it.
//
// Obstacle avoidance (inequality constraints): an avoidance link is a chain
// to a rigid body whose minimum distance to an obstacle was measured at
// the start of the solve (distance d0, witness point p on the link, unit
// normal n away from the obstacle). The distance is estimated as
// d0 + n . (p(q) - p), p moving with the link; while the estimate is below
// the link's clearance, a row n^T J_p = clearance - estimate joins the
// system (an active set), so the redundant joints push the link out.
//
// The solve stops when every element is within tolerance and every link
// clear, or after max_iterations. Conditional solving: with
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

// One avoidance link's measurement at the start of a solve.
struct IkClearance {
  bool near = false;    // measured within reach: the rest is valid
  double distance = 0;  // m, now
  Vec3 p_WL;            // witness point on the link (world)
  Vec3 n_W;             // unit normal, from the obstacle towards the link
  Pose X_WLink;         // the link's pose when measured
};

inline constexpr int kMaxIkDof = 32;
inline constexpr int kMaxIkElements = 4;
inline constexpr int kMaxIkAvoidLinks = 16;

class IkProblem {
 public:
  // Returns the element index.
  int AddElement(Chain chain, const Pose& X_WTarget, uint8_t constraints = kPose);
  // An element whose target hangs below the same base through joints (a
  // closed chain): the target moves with q too; its chain's joints are
  // unknowns as well. Both chains start at the same base.
  int AddClosedElement(Chain tip_chain, Chain target_chain, uint8_t constraints = kPose);
  // An avoidance link: the chain from the same base to the link's frame,
  // kept at least `clearance` m from what set_clearance measures. Returns
  // its index.
  int AddAvoidLink(Chain link_chain, double clearance);
  void set_target(int element, const Pose& X_WTarget) {
    elements_.at(element).X_WTarget = X_WTarget;
  }
  // Moving bases: the world pose of an element's base (both its chains).
  void set_base_pose(int element, const Pose& X_WBase);
  void set_avoid_base_pose(int link, const Pose& X_WBase) {
    avoid_.at(link).chain.set_X_WBase(X_WBase);
  }
  void set_clearance(int link, const IkClearance& reading) { avoid_.at(link).reading = reading; }
  int avoid_link_count() const { return static_cast<int>(avoid_.size()); }
  const Chain& chain(int element) const { return elements_.at(element).chain; }

  // The unknowns: scene slots of the joints, in column order (a spherical
  // joint's slot three times).
  int dof() const { return static_cast<int>(slots_.size()); }
  std::span<const uint32_t> joint_slots() const { return slots_; }
  // Is column c the first of a spherical joint's three?
  bool is_ball(int column) const { return kind_.at(column) == kBallX; }
  bool is_ball_part(int column) const { return kind_.at(column) != kOne; }
  void set_weight(int column, double weight) { weights_.at(column) = weight; }
  // Frozen columns keep their value (the joint's IK mode), until unfrozen.
  void set_frozen(int column, bool frozen) { frozen_.at(column) = frozen; }
  // Column `column` follows `master`: q = offset + factor * q_master (both
  // one-column joints).
  void SetDependent(int column, int master, double factor, double offset);

  // Positions of the unknowns in the scene / written back to it (a
  // spherical joint's columns: 0, its rotation is its `ball`).
  std::vector<double> ReadPositions(const Scene& scene) const;
  void WritePositions(std::span<const double> q, Scene* scene) const;

  // Solves from q (size dof()), updating it (see apply_only_when_solved).
  // `ball` (size dof(), null: the rotations at extraction, not returned)
  // holds each spherical joint's rotation at its first column.
  IkResult Solve(const IkSettings& settings, std::vector<double>* q,
                 std::vector<Quat>* ball = nullptr) const;

 private:
  enum ColumnKind : uint8_t { kOne, kBallX, kBallY, kBallZ };
  struct Element {
    Chain chain;
    Pose X_WTarget;
    uint8_t constraints = kPose;
    std::vector<int> columns;  // per chain joint: its (first) column
    bool closed = false;       // target_chain gives the target
    Chain target_chain;
    std::vector<int> target_columns;  // per target chain joint
  };
  struct AvoidLink {
    Chain chain;
    std::vector<int> columns;  // per chain joint
    double clearance = 0;      // m
    IkClearance reading;
  };
  int AddColumn(const ChainJoint& joint);
  std::vector<Element> elements_;
  std::vector<AvoidLink> avoid_;
  // Per column.
  std::vector<uint32_t> slots_;
  std::vector<double> weights_, min_, max_;
  std::vector<uint8_t> kind_, frozen_;
  std::vector<int> master_;  // dependent columns: the master's column, else -1
  std::vector<double> factor_, offset_;
  std::vector<Quat> ball0_;  // spherical joints' rotation at extraction
};

}  // namespace swarmsim::kinematics
