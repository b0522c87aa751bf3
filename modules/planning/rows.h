// The `planning_task` object type's row (objects.cc) and how the module and
// the Lua area find it. Internal to modules/planning.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/scene.h"
#include "modules/planning/planner.h"

namespace swarmsim::planning {

inline constexpr const char* kTypeName = "planning_task";
inline constexpr const char* kModuleName = "planning";

struct PlanningTaskRow {
  // Settings (the file's, adjusted by sim.setPlanningTask).
  Space space = Space::kSe2;
  std::string robot = ":";                // entity whose shapes move (object path or collection)
  std::string obstacles = "environment";  // `environment`, `everything_else` or a path
  bool has_bounds = false;                // else the static shapes' extent (the arena)
  Vec3 lo, hi;                            // m, the bounds when given
  double turning_radius = 0.5;            // m, car-like spaces
  double resolution = 0.05;               // m
  double time_limit = 1;                  // s, > 0 (a deterministic iteration budget)
  std::string where;                      // "file:line:column" of the entry, for errors
  // The request a script made this step (sim.planPath), run in the actuate phase.
  bool requested = false;
  Pose goal;
  double request_time_limit = 1;
  uint64_t seed = 0;  // drawn from the robot's random stream when requested
  // The last result; the plan's path object (a scene root, world frame),
  // made when the world starts (or, for a copy, at its first plan).
  PlanStatus status = PlanStatus::kNone;
  std::string reason;
  std::vector<Pose> waypoints;
  std::vector<Pose> dense;
  int64_t iterations = 0;
  ObjectId path;
};

// The scene's task rows, or null if the type is not registered.
inline Rows<PlanningTaskRow>* TaskRows(Scene* scene) {
  ObjectType type;
  if (!scene->FindType(kTypeName, &type)) return nullptr;
  return static_cast<Rows<PlanningTaskRow>*>(scene->rows(type));
}

}  // namespace swarmsim::planning
