// Small helpers the ODE module's files share: poses and vectors between ODE
// and the framework, and a 64-bit mixer. Internal to the module.
#pragma once

#include <ode/ode.h>

#include <cstdint>

#include "framework/math.h"

namespace swarmsim::ode {

inline void SetBodyPose(dBodyID body, const Pose& X) {
  dBodySetPosition(body, X.p.x, X.p.y, X.p.z);
  const dQuaternion q = {X.q.w, X.q.x, X.q.y, X.q.z};
  dBodySetQuaternion(body, q);
}

inline Pose BodyPose(dBodyID body) {
  const dReal* p = dBodyGetPosition(body);
  const dReal* q = dBodyGetQuaternion(body);
  return {{p[0], p[1], p[2]}, {q[0], q[1], q[2], q[3]}};
}

inline Vec3 ToVec3(const dReal* v) { return {v[0], v[1], v[2]}; }

// splitmix64's finalizer.
inline uint64_t Mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// A draw in [0, n) from the high bits of `z` (0 when n <= 1).
inline int Below(uint64_t z, int n) {
  return n > 1 ? static_cast<int>(((z >> 32) * static_cast<uint64_t>(n)) >> 32) : 0;
}

// ODE initialised for the process (once; ode_process.cc), and whether ODE's
// quickstep calls the program's dRandInt (else the solver stays on one thread).
void InitOdeOnce();
bool SolverShuffleIsOurs();

}  // namespace swarmsim::ode
