// The seam between swarmsim and its OMPL module (libswarmsim_ompl.so, built
// from planner.cc): OMPL and Boost's serialization and filesystem libraries
// (~3.7 MB resident) are mapped only when a world plans a path. plan.cc
// opens the module on first use (framework/shared_library.h says where it is
// looked for); no OMPL type crosses the seam. Both sides come from one build
// (kOmplModuleVersion guards a stale module).
#pragma once

#include "modules/planning/planner.h"

namespace swarmsim::planning {

// Bumped whenever anything in this file or in planner.h's types changes.
inline constexpr int kOmplModuleVersion = 1;

// What the module exports, through kOmplModuleEntry.
struct OmplModule {
  int version = 0;  // kOmplModuleVersion of the module's build
  // Plan (planner.h), on OMPL; OMPL's console is silent.
  PlanResult (*plan)(const PlanRequest& request, const ValidityFn& valid) = nullptr;
};

// The module's one exported symbol: extern "C" const void* NAME(), the
// module's OmplModule.
inline constexpr const char* kOmplModuleEntry = "swarmsim_ompl_module";

// The environment variable naming the module's file instead.
inline constexpr const char* kOmplModuleVariable = "SWARMSIM_OMPL_MODULE";

}  // namespace swarmsim::planning
