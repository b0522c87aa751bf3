// modules/graphs: graph objects (paper §2.1). A `graph` records data
// streams (an object's position, orientation or velocity, a joint's
// position, a proximity or force sensor's reading, a distance object's
// result, a value a script sets with sim.setGraphStreamValue) after each
// step, as a time graph, an X/Y curve or a 3D curve; each run with an
// output folder gets them as CSV and PNG (gnuplot) in <out>/graphs/, listed
// in summary.json. A graph inside a model is per copy.
#pragma once

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::graphs {

// The module and its object type.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::graphs
