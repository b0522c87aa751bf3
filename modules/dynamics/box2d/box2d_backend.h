// Box2D 2.4 dynamics: a top-down plane of robots and obstacles.
#pragma once

#include <memory>

#include "framework/dynamics_backend.h"
#include "framework/registry.h"

namespace swarmsim::box2d {

swarmsim::ModuleInfo ModuleInfo();
std::unique_ptr<DynamicsBackend> MakeBackend();

}  // namespace swarmsim::box2d
