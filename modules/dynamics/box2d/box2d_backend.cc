// PLACEHOLDER until the Box2D backend lands.
#include "modules/dynamics/box2d/box2d_backend.h"
namespace swarmsim::box2d {
swarmsim::ModuleInfo ModuleInfo() { return {"dynamics", "box2d", "0", "placeholder"}; }
std::unique_ptr<DynamicsBackend> MakeBackend() { return nullptr; }
}  // namespace swarmsim::box2d
