// An example plugin (framework/plugin_api.h): two script commands.
//   sim.exampleSum(a, b, ...) or sim.exampleSum({a, b, ...}) -> the sum
//   sim.exampleWhereAmI() -> {x, y, z} of the calling script's object, and the robot index
#include <cstdio>

#include "framework/plugin_api.h"

namespace {

int Sum(const SwarmsimCallContext*, const SwarmsimValue* args, int n, SwarmsimValue* results,
        int, char* error, size_t error_size, void*) {
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    if (args[i].type == kSwarmsimNumber) {
      sum += args[i].number;
    } else if (args[i].type == kSwarmsimNumbers) {
      for (size_t k = 0; k < args[i].size; ++k) sum += args[i].numbers[k];
    } else {
      std::snprintf(error, error_size, "argument %d must be a number or an array of numbers", i + 1);
      return -1;
    }
  }
  results[0] = {kSwarmsimNumber, sum, nullptr, nullptr, 0};
  return 1;
}

int WhereAmI(const SwarmsimCallContext* c, const SwarmsimValue*, int, SwarmsimValue* results, int,
             char* error, size_t error_size, void*) {
  thread_local double p[3];  // results stay valid until the command returns
  if (!c->api->object_position(c->world, c->script_object, p)) {
    std::snprintf(error, error_size, "only a child script has an object");
    return -1;
  }
  results[0] = {kSwarmsimNumbers, 0, nullptr, p, 3};
  results[1] = {kSwarmsimNumber, static_cast<double>(c->robot), nullptr, nullptr, 0};
  return 2;
}

}  // namespace

extern "C" int swarmsim_plugin_abi_version(void) { return SWARMSIM_PLUGIN_ABI_VERSION; }

extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar* r) {
  r->set_info(r->impl, "example", "1.0", "example plugin: exampleSum, exampleWhereAmI");
  if (r->add_command(r->impl, "exampleSum", "sum of numbers and number arrays", Sum, nullptr) != 0)
    return -1;
  return r->add_command(r->impl, "exampleWhereAmI", "position of the calling script's object",
                        WhereAmI, nullptr);
}
