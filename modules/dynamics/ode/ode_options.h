// Settings of the ODE backend (see ode_backend.h for what they mean). Its own
// header so that the backend and its world can both include it without
// including each other.
#pragma once

#include <cstdint>

namespace swarmsim::ode {

struct Options {
  int iterations = 40;         // quickstep iterations; 0: dWorldStep (exact, slower)
  int max_contacts = 4;        // contact points per geom pair
  bool ground_plane = true;    // a static plane at z = 0
  double ground_friction = 1;  // Coulomb coefficient of the ground plane
  double erp = 0.2;            // ODE's error reduction parameter
  double cfm = 1e-6;           // ODE's constraint force mixing
  uint32_t seed = 1;           // seeds the solver's constraint shuffles (ode_world.cc, dRandInt)
};

}  // namespace swarmsim::ode
