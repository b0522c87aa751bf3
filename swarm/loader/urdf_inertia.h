// Mass properties of URDF links and of the bodies merged from them
// (urdf.cc): a link's <inertial> in its link frame, a group of links joined
// by fixed joints combined about its common centre of mass (parallel-axis
// theorem, each part rotated into the group's frame), and the repair of
// inertias no rigid body has (MuJoCo's `balanceinertia`). No urdf:: types.
#pragma once

#include <array>

#include "framework/math.h"

namespace swarmsim::loader {

// A symmetric inertia tensor: (ixx, iyy, izz, ixy, ixz, iyz), kg m^2.
using Inertia = std::array<double, 6>;

struct MassProperties {
  double mass = 0;    // kg
  Vec3 center;        // m: the centre of mass in the frame
  Inertia inertia{};  // kg m^2: about `center`, in the frame's axes
};

// `part` (in frame A) expressed in frame B: X_BA moves its centre, and
// rotates its inertia (R I R^T).
MassProperties Transformed(const MassProperties& part, const Pose& X_BA);

// `part` added to `sum` (both in one frame): the combined mass, centre of
// mass, and inertia about that centre (each inertia shifted by the
// parallel-axis theorem, m (|d|^2 E - d d^T), d its centre from the new one).
void AddMass(const MassProperties& part, MassProperties* sum);

// The principal moments of `inertia` (its eigenvalues), ascending.
std::array<double, 3> PrincipalMoments(const Inertia& inertia);

// Whether a rigid body can have `inertia`: finite, positive definite (the
// smallest principal moment above kMinMomentRatio times the largest) and
// each principal moment at most the sum of the other two (1e-9 of the
// trace of slack).
inline constexpr double kMinMomentRatio = 1e-9;
bool InertiaIsPhysical(const Inertia& inertia);

// MuJoCo's `balanceinertia`: every principal moment replaced by their mean
// (trace / 3), about the same centre: an isotropic tensor, whatever the
// axes. The trace is the same in every frame, so is the mean.
Inertia BalancedInertia(const Inertia& inertia);

}  // namespace swarmsim::loader
