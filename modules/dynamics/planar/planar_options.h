// Settings of the planar backend (planar_backend.h); the defaults are what
// `physics: planar` runs with.
#pragma once

namespace swarmsim::planar {

struct Options {
  // Jacobi passes of overlap resolution per internal step, at most (they stop
  // early once no two bodies overlap by more than `tolerance`).
  int iterations = 4;
  // Overlap left between bodies that ends the passes, m.
  double tolerance = 1e-4;
  // No body moves more than this fraction of its inner radius (circle: its
  // radius; rectangle: its smaller half extent) in one internal step.
  double max_move_fraction = 0.25;
  // Internal steps per Step at most (a cap for absurd wheel speeds).
  int max_internal_steps = 1000;
};

}  // namespace swarmsim::planar
