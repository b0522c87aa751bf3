// The planner's front (planner.h): space names, and Plan on the OMPL module
// (ompl_module.h), opened on first use.
#include <string>
#include <utility>

#include "framework/error.h"
#include "framework/shared_library.h"
#include "modules/planning/ompl_module.h"
#include "modules/planning/planner.h"

namespace swarmsim::planning {

namespace {

// Set by modules/planning/CMakeLists.txt: the module's file name and where
// this build put it.
#ifndef SWARMSIM_OMPL_MODULE_NAME
#define SWARMSIM_OMPL_MODULE_NAME "libswarmsim_ompl.so"
#endif
#ifndef SWARMSIM_OMPL_MODULE_PATH
#define SWARMSIM_OMPL_MODULE_PATH ""
#endif

// The module, once per process: a failure is kept and thrown again.
const OmplModule& Ompl() {
  static const LazyOwnLibrary library(
      OwnLibrary{SWARMSIM_OMPL_MODULE_NAME, SWARMSIM_OMPL_MODULE_PATH, kOmplModuleVariable,
                 kOmplModuleEntry, kOmplModuleVersion,
                 "path planning needs swarmsim's OMPL module (" SWARMSIM_OMPL_MODULE_NAME
                 ", on OMPL 1.5: Debian's libompl16, which tools/setup.sh installs)"});
  return *static_cast<const OmplModule*>(library.Get());
}

}  // namespace

bool ParseSpace(const std::string& text, Space* space) {
  static constexpr std::pair<const char*, Space> kNames[] = {{"se2", Space::kSe2},
                                                             {"se3", Space::kSe3},
                                                             {"dubins", Space::kDubins},
                                                             {"reeds_shepp", Space::kReedsShepp}};
  for (const auto& [name, value] : kNames)
    if (text == name) {
      *space = value;
      return true;
    }
  return false;
}

const char* SpaceName(Space space) {
  switch (space) {
    case Space::kSe2: return "se2";
    case Space::kSe3: return "se3";
    case Space::kDubins: return "dubins";
    case Space::kReedsShepp: return "reeds_shepp";
  }
  return "?";
}

void LoadPlanner() { Ompl(); }

PlanResult Plan(const PlanRequest& request, const ValidityFn& valid) {
  return Ompl().plan(request, valid);
}

}  // namespace swarmsim::planning
