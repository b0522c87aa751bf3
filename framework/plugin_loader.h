// Loading plugins (framework/plugin_api.h): shared libraries that register
// script commands into a ModuleRegistry.
#pragma once

#include <string>

namespace swarmsim {

class ModuleRegistry;

// dlopen()s `path` and runs its swarmsim_plugin_register into `registry`.
// Throws swarmsim::Error naming the path when the library cannot be opened,
// lacks an entry point, was built for another ABI version, or fails to
// register. Libraries stay loaded for the life of the process.
void LoadPlugin(const std::string& path, ModuleRegistry* registry);

}  // namespace swarmsim
