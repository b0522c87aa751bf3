// Settings of the Box2D backend (see box2d_backend.h for what they mean).
// Its own header so that the backend and its world can both include it
// without including each other.
#pragma once

namespace swarmsim::box2d {

// Box2D units per metre; see "Length scale" in box2d_backend.h.
inline constexpr double kDefaultLengthScale = 10.0;

struct Options {
  double length_scale = kDefaultLengthScale;  // Box2D units per metre
  int velocity_iterations = 8;                // Box2D's contact solver
  int position_iterations = 3;
  int traction_iterations = 4;  // Gauss-Seidel passes over a body's wheels
};

}  // namespace swarmsim::box2d
