// The planner (internal to modules/planning; OMPL types stay in planner.cc,
// built as a module of its own that Plan opens on first use: ompl_module.h):
// one request -> one plan, deterministic. Holonomic spaces (se2, se3) use
// RRT-Connect, car-like ones (dubins, reeds_shepp) RRT with a 5 % goal bias.
//
// Determinism: every random draw comes from Rng(seed) (framework/random.h)
// through a state sampler of our own; the planners' own RNGs are seeded
// from it too, nearest neighbours are exact (GNAT: its random pivots shape
// the tree, never the answer) or, in the car-like spaces that are no metric,
// OMPL's sqrt-approximate search (no randomness), simplification is a greedy shortcut (no random
// shortcuts), and the time limit is a budget of planner iterations (kIterationsPerSecond per second
// of `time_limit`), never the wall clock. Same request, same plan, on any
// thread and under any load.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "framework/math.h"

namespace swarmsim::planning {

enum class Space : uint8_t { kSe2, kSe3, kDubins, kReedsShepp };
// "se2", "se3", "dubins", "reeds_shepp"; false for anything else.
bool ParseSpace(const std::string& text, Space* space);
const char* SpaceName(Space space);
inline bool IsPlanar(Space space) { return space != Space::kSe3; }

// Planner iterations one second of a time limit buys (about what a 2-core
// VM runs in a cluttered 20 x 20 m map with one box robot).
inline constexpr double kIterationsPerSecond = 20000;

struct PlanRequest {
  Space space = Space::kSe2;
  Vec3 lo, hi;                // m: the box the robot's frame stays in (z ignored when planar)
  double turning_radius = 1;  // m, car-like spaces
  double resolution = 0.05;   // m (and rad x 0.1 m) between the states a motion is checked at
  double time_limit = 1;      // s, > 0: a budget of time_limit x kIterationsPerSecond iterations
  uint64_t seed = 0;
  Pose start, goal;  // the robot frame's world poses (planar: x, y, yaw; z from start)
};

enum class PlanStatus : uint8_t { kNone, kPending, kSolved, kFailed };

struct PlanResult {
  PlanStatus status = PlanStatus::kNone;
  // "solved", "timeout", "invalid start: in collision", "invalid start:
  // outside bounds", "invalid goal: in collision", "invalid goal: outside
  // bounds", "goal enclosed/unreachable", "start enclosed/unreachable".
  std::string reason;
  std::vector<Pose> waypoints;  // the simplified plan's states, start to goal
  std::vector<Pose> dense;      // the same, interpolated every `resolution` m
  int64_t iterations = 0;       // planner iterations spent
};

// Is the robot frame at X_WR free of collision? Called from the planning thread only.
using ValidityFn = std::function<bool(const Pose& X_WR)>;

// Opens the OMPL module on first use; throws swarmsim::Error naming the
// paths tried when it cannot be loaded.
PlanResult Plan(const PlanRequest& request, const ValidityFn& valid);

// Opens the OMPL module now if it is not open (Plan does on first use):
// a caller about to plan on worker threads hears a missing module on its
// own. Throws swarmsim::Error naming the paths tried.
void LoadPlanner();

}  // namespace swarmsim::planning
