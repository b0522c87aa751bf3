// The "ik" calculation module: IK groups stored world-side, solved each
// actuate phase one robot per task (groups of a robot in handle order),
// duplicated and removed with their model (framework/ik_groups.h).
#pragma once

#include <memory>

#include "framework/ik_groups.h"
#include "framework/registry.h"

namespace swarmsim::kinematics {

ModuleInfo IkModuleInfo();
std::unique_ptr<IkGroups> MakeIkGroups();

}  // namespace swarmsim::kinematics
