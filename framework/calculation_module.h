// Calculation modules that work on calculation objects (paper §2.2): IK
// groups today, later minimum-distance objects or path followers. They are
// ordinary modules (framework/module.h) of kind "calculation", registered
// with ModuleRegistry::RegisterCalculation and run in the actuate phase.
#pragma once

#include "framework/module.h"

namespace swarmsim {

using CalculationModule = Module;

}  // namespace swarmsim
