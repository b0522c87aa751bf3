// The module registry of the harnesses that load worlds (its own file, so
// that the other harnesses do not link the modules).
#include "framework/registry.h"
#include "modules/builtin.h"
#include "tools/fuzz/fuzz_support.h"

namespace swarmsim::fuzz {

const ModuleRegistry& Registry() {
  static const ModuleRegistry* registry = [] {
    auto* r = new ModuleRegistry;  // never freed: used until exit
    RegisterBuiltinModules(r);
    return r;
  }();
  return *registry;
}

}  // namespace swarmsim::fuzz
