// Settings of the ODE backend (see ode_backend.h for what they mean). Its own
// header so that the backend and its world can both include it without
// including each other. A world file sets them in `simulation: {physics:
// ode, ode: {...}}` (ode_section.cc; worlds/README.md, "ODE settings").
#pragma once

#include <cstdint>
#include <memory>

#include "framework/dynamics_backend.h"

namespace swarmsim::ode {

// Which ODE stepper solves the constraints.
enum class Solver : uint8_t {
  kAuto,       // kWorld for worlds of at most kExactSolverBodies dynamic bodies, two
               // thirds of them hanging from a fixed base (arms), else kQuickStep
  kWorld,      // dWorldStep: exact (Dantzig LCP) per island; cost grows with rows^3
  kQuickStep,  // dWorldQuickStep: `iterations` sweeps of projected Gauss-Seidel
};

// `auto` takes the exact solver up to this many dynamic bodies (an arm, a few
// legged robots), quickstep above (swarms, where the solver is the cost) and
// for worlds of mostly free bodies (stacks of boxes, floating robots on the
// ground, where the exact solve degenerates).
constexpr int kExactSolverBodies = 64;

struct Options {
  Solver solver = Solver::kAuto;
  int iterations = 40;         // quickstep iterations (0: dWorldStep, as solver kWorld)
  int max_contacts = 4;        // contact points per geom pair
  bool ground_plane = true;    // a static plane at z = 0
  double ground_friction = 1;  // Coulomb coefficient of the ground plane
  double erp = 0.2;            // ODE's error reduction parameter
  double cfm = 1e-6;           // ODE's constraint force mixing
  // Joint limits (ODE's stops): their ERP and CFM, for joints that do not
  // set their own (limit_erp, limit_cfm); negative: erp's and cfm's values.
  double limit_erp = -1;
  double limit_cfm = -1;
  uint32_t seed = 1;  // seeds the solver's constraint shuffles (ode_world.cc, dRandInt)
};

// Options as a world file gives them (WorldSettings::physics_options).
struct WorldOptions final : DynamicsOptions {
  Options options;
};

}  // namespace swarmsim::ode
