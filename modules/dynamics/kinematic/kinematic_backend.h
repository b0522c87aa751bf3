// The kinematic backend (`physics: kinematic`): no dynamics engine at all.
// Objects move only by scripts, IK and joint targets (World::Actuate moves
// every joint toward its target), the fast path for stiff, fixed robots.
// Dynamic flags are ignored: nothing falls, nothing collides.
#pragma once

#include <memory>

#include "framework/dynamics_backend.h"
#include "framework/registry.h"

namespace swarmsim::kinematic {

swarmsim::ModuleInfo ModuleInfo();
std::unique_ptr<DynamicsBackend> MakeBackend();

}  // namespace swarmsim::kinematic
