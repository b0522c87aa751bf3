// Registers every module built into swarmsim with a registry.
#pragma once

namespace swarmsim {
class ModuleRegistry;
void RegisterBuiltinModules(ModuleRegistry* registry);
}  // namespace swarmsim
