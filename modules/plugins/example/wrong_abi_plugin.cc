// A plugin built for another ABI version (tests the check).
#include "framework/plugin_api.h"

extern "C" int swarmsim_plugin_abi_version(void) { return SWARMSIM_PLUGIN_ABI_VERSION + 1; }
extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar*) { return 0; }
