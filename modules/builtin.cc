#include "modules/builtin.h"

#include "framework/registry.h"
#include "modules/dynamics/box2d/box2d_backend.h"
#include "modules/dynamics/kinematic/kinematic_backend.h"
#include "modules/dynamics/ode/ode_backend.h"
#include "modules/kinematics/ik_groups.h"
#include "modules/proximity/proximity.h"

namespace swarmsim {

void RegisterBuiltinModules(ModuleRegistry* registry) {
  registry->RegisterDynamics(box2d::ModuleInfo(), [] { return box2d::MakeBackend(); });
  registry->RegisterDynamics(ode::ModuleInfo(), [] { return ode::MakeBackend(); });
  registry->RegisterDynamics(kinematic::ModuleInfo(), [] { return kinematic::MakeBackend(); });
  registry->RegisterProximity(proximity::ModuleInfo(), [] { return proximity::MakeBackend(); });
  registry->RegisterCalculation(kinematics::IkModuleInfo(),
                                [] { return kinematics::MakeIkGroups(); });
}

}  // namespace swarmsim
