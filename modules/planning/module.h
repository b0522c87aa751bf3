// The planning module's instance: runs the plans scripts requested in the
// control phase, robots in parallel, in the actuate phase (internal to
// modules/planning).
#pragma once

#include <vector>

#include "framework/module.h"
#include "modules/planning/planner.h"

namespace swarmsim::planning {

struct PlanningTaskRow;

class PlanningModule final : public Module {
 public:
  // Snapshots (framework/world_state.h): its objects' rows (no save_rows) make
  // World::SaveState refuse while the world has any; without them it is idle.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  // Makes each task's result path.
  void Start(World* world) override;
  // Plans every requested task (tasks in parallel, each on one worker,
  // results written in row order) and writes each solved plan into its path.
  void Actuate(World* world) override;

  // The request task row `r` of `scene` would plan now (start: the robot's
  // pose; bounds resolved). Throws swarmsim::Error naming the task.
  static PlanRequest MakeRequest(const Scene& scene, uint32_t owner, const PlanningTaskRow& t);

 private:
  // Every task without a result path gets one (a root path object).
  static void EnsurePaths(Scene* scene);
};

}  // namespace swarmsim::planning
