// A native controller that uses the range-and-bearing board through the
// plugin world API (ABI 7), for tests/modules/range_and_bearing/
// native_test.cc: every step it reads its robot's board ./rab and sends
// {robot index, readings heard, first byte of the nearest reading (0 if
// none), 0, ...}; with a parameter `too_long` = 1 it tries to send one
// byte more than the payload and fails the step with the API's answer.
#include <cstdio>
#include <cstdlib>

#include "framework/plugin_api.h"

namespace {

int Init(const SwarmsimCallContext* c, void** state, char* error, size_t error_size, void*) {
  int64_t board = 0;
  if (c->api->find_object(c->world, c->script_object, "./rab", &board) == 0) {
    std::snprintf(error, error_size, "no ./rab");
    return -1;
  }
  auto* own = static_cast<int64_t*>(std::malloc(sizeof(int64_t)));
  if (own == nullptr) return -1;
  *own = board;
  *state = own;
  return 0;
}

int Step(const SwarmsimCallContext* c, void* state, char* error, size_t error_size, void*) {
  const int64_t board = *static_cast<int64_t*>(state);
  SwarmsimRangeAndBearingReading readings[8];
  const int n = c->api->read_range_and_bearing(c->world, board, readings, 8);
  if (n < 0) {
    std::snprintf(error, error_size, "read_range_and_bearing failed");
    return -1;
  }
  const uint8_t data[3] = {
      static_cast<uint8_t>(c->robot), static_cast<uint8_t>(n),
      static_cast<uint8_t>(n > 0 && readings[0].size > 0 ? readings[0].data[0] : 0)};
  double too_long = 0;
  c->api->number_parameter(c->world, c->robot, "too_long", &too_long);
  const uint8_t big[11] = {};
  const int r = too_long != 0
                    ? c->api->set_range_and_bearing_data(c->world, c->robot, board, big, 11)
                    : c->api->set_range_and_bearing_data(c->world, c->robot, board, data, 3);
  if (r != 0) {
    std::snprintf(error, error_size, "set_range_and_bearing_data refused");
    return -1;
  }
  return 0;
}

void Cleanup(const SwarmsimCallContext*, void* state, void*) { std::free(state); }

}  // namespace

extern "C" int swarmsim_plugin_abi_version(void) { return SWARMSIM_PLUGIN_ABI_VERSION; }

extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar* r) {
  r->set_info(r->impl, "rab_echo", "1.0", "tells the others what its board hears (a test)");
  return r->add_controller(r->impl, "rab_echo", "range-and-bearing echo", Init, Step, Cleanup,
                           nullptr);
}
