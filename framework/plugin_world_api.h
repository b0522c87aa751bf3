// The world interface plugins see (SwarmsimWorldApi, framework/plugin_api.h):
// one table of functions taking the World as `void* world`.
#pragma once

#include "framework/plugin_api.h"

namespace swarmsim {

const SwarmsimWorldApi* PluginWorldApi();

}  // namespace swarmsim
