// modules/mill: mills (paper §2.1), convex cutting volumes attached to
// objects, and cuttable voxel blocks: the `mill` and `cuttable` object
// types, cut after physics each step (robots' searches in parallel,
// applied in mill order) and recorded into metrics.csv and mill.csv; mills
// also cut the environment map. Scripts: sim.setMillEnabled, sim.readMill,
// sim.readCuttable.
#pragma once

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::mill {

// The module and its two object types.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::mill
