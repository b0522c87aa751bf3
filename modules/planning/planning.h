// modules/planning: path planning on OMPL 1.5 (paper §2.2, issue 15): the
// `planning_task` type (a calculation object: state space, robot,
// obstacles, bounds, time limit), planned in the actuate phase robots in
// parallel, deterministically, the result written into a path object
// (modules/paths), and the scripts' sim.planPath, sim.readPlan,
// sim.getPlanStates, sim.setPlanningTask.
#pragma once

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::planning {

// The module and the `planning_task` type.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::planning
