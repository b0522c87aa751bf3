// PLACEHOLDER until the proximity module lands.
#include "modules/proximity/proximity.h"
namespace swarmsim::proximity {
swarmsim::ModuleInfo ModuleInfo() { return {"proximity", "proximity", "0", "placeholder"}; }
std::unique_ptr<ProximityBackend> MakeBackend() { return nullptr; }
}  // namespace swarmsim::proximity
