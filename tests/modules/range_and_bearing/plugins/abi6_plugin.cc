// A plugin built for plugin ABI 6 (before the range-and-bearing functions of
// ABI 7 were added at the end of SwarmsimWorldApi): it must still load and
// run. Its command sim.abi6Time() returns the world's time through the API.
#include "framework/plugin_api.h"

namespace {

int Time(const SwarmsimCallContext* c, const SwarmsimValue*, int, SwarmsimValue* results, int max,
         char*, size_t, void*) {
  if (max < 1) return 0;
  results[0].type = kSwarmsimNumber;
  results[0].number = c->api->time(c->world);
  return 1;
}

}  // namespace

extern "C" int swarmsim_plugin_abi_version(void) { return 6; }

extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar* r) {
  r->set_info(r->impl, "abi6", "1.0", "a plugin of ABI 6 (a test)");
  return r->add_command(r->impl, "abi6Time", "the world's time", Time, nullptr);
}
