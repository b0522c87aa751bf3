// A native controller on the plugin world API of ABI 8, for
// tests/modules/ir_messaging/native_test.cc: what a Kilobot's firmware
// does through it. Each step, for the robot's ./ir, ./light, ./ground and
// ./led:
//   - robot 0 sends {1, its light reading x 100, its ground value x 100};
//   - robot k > 0 relays the first message it heard with byte 0 = k (from
//     robot k - 1's side of the chain), with byte 0 plus one (the hops);
//   - the LED turns red when it heard something this step, green when its
//     light reading is above zero (both: yellow);
//   - wrong handles must be refused (-1): the step fails otherwise.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "framework/plugin_api.h"

namespace {

struct Devices {
  int64_t ir, light, ground, led;
};

int Init(const SwarmsimCallContext* c, void** state, char* error, size_t error_size, void*) {
  Devices d{};
  const SwarmsimWorldApi* api = c->api;
  if (api->find_object(c->world, c->script_object, "./ir", &d.ir) == 0 ||
      api->find_object(c->world, c->script_object, "./light", &d.light) == 0 ||
      api->find_object(c->world, c->script_object, "./ground", &d.ground) == 0 ||
      api->find_object(c->world, c->script_object, "./led", &d.led) == 0) {
    std::snprintf(error, error_size, "a device is missing");
    return -1;
  }
  auto* own = static_cast<Devices*>(std::malloc(sizeof(Devices)));
  if (own == nullptr) return -1;
  *own = d;
  *state = own;
  return 0;
}

uint8_t Byte(double v) { return static_cast<uint8_t>(std::lround(std::fmin(255, v * 100))); }

int Step(const SwarmsimCallContext* c, void* state, char* error, size_t error_size, void*) {
  const Devices& d = *static_cast<Devices*>(state);
  const SwarmsimWorldApi* api = c->api;
  double light = 0, ground = 0;
  if (api->read_sensor_value(c->world, d.light, &light) != 0 ||
      api->read_sensor_value(c->world, d.ground, &ground) != 0) {
    std::snprintf(error, error_size, "read_sensor_value failed");
    return -1;
  }
  SwarmsimIrMessage heard[4];
  const int n = api->ir_receive(c->world, d.ir, heard, 4);
  const int sent = api->ir_sent(c->world, d.ir);
  if (n < 0 || sent < 0) {
    std::snprintf(error, error_size, "ir_receive or ir_sent failed");
    return -1;
  }
  // What must be refused: the wrong kind of object, too many bytes, another robot's LED.
  const uint8_t big[13] = {};
  double unused = 0;
  int64_t other_led = 0;
  api->find_object(c->world, 0, c->robot == 0 ? "/irbot#1/led" : "/irbot#0/led", &other_led);
  if (api->ir_send(c->world, c->robot, d.led, big, 1) != -1 ||
      api->ir_send(c->world, c->robot, d.ir, big, 13) != -1 ||
      api->read_sensor_value(c->world, d.ir, &unused) != -1 ||
      api->ir_sent(c->world, d.led) != -1 || api->ir_receive(c->world, d.led, heard, 4) != -1 ||
      api->set_led(c->world, c->robot, d.ir, 1, 1, 1, 1) != -1 ||
      api->set_led(c->world, c->robot, other_led, 1, 1, 1, 1) != -1) {
    std::snprintf(error, error_size, "a wrong call was accepted");
    return -1;
  }
  int r = 0;
  if (c->robot == 0) {
    const uint8_t data[3] = {1, Byte(light), Byte(ground)};
    r = api->ir_send(c->world, c->robot, d.ir, data, 3);
  } else {
    for (int k = 0; k < n && k < 4; ++k) {
      if (heard[k].size == 0 || heard[k].data[0] != c->robot) continue;
      uint8_t data[12];
      const size_t size = heard[k].size < 12 ? heard[k].size : 12;
      for (size_t i = 0; i < size; ++i) data[i] = heard[k].data[i];
      data[0] = static_cast<uint8_t>(data[0] + 1);
      r = api->ir_send(c->world, c->robot, d.ir, data, size);
      break;
    }
  }
  // Colours out of range are clamped (red 2 -> 1).
  if (r != 0 || api->set_led(c->world, c->robot, d.led, n > 0 ? 2 : 0, light > 0 ? 1 : 0, 0, 1)) {
    std::snprintf(error, error_size, "ir_send or set_led refused");
    return -1;
  }
  return 0;
}

void Cleanup(const SwarmsimCallContext*, void* state, void*) { std::free(state); }

}  // namespace

extern "C" int swarmsim_plugin_abi_version(void) { return SWARMSIM_PLUGIN_ABI_VERSION; }

extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar* r) {
  r->set_info(r->impl, "ir_relay", "1.0", "relays IR messages, reads light, sets an LED (a test)");
  return r->add_controller(r->impl, "ir_relay", "IR relay", Init, Step, Cleanup, nullptr);
}
