// Narrow services for the plugins' C API (plugin_world_api.cc, ABI 8:
// read_sensor_value, set_led, ir_send, ir_sent, ir_receive), which names
// no module: each module's world instance (World::find_module) implements
// the interface of its devices, as range_and_bearing_access.h does for the
// range-and-bearing boards. Without the module no object is such a device.
//   "light"         SensorValueAccess  light_sensor readings (modules/light)
//   "ground_sensor" SensorValueAccess  ground_sensor values (modules/ground_sensor)
//   "blobs"         LedAccess          led rows (modules/blobs)
//   "ir_messaging"  IrAccess           ir_transceiver rows (modules/ir_messaging)
// None of these throws: they are called from C.
#pragma once

#include <cstddef>
#include <cstdint>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/plugin_api.h"

namespace swarmsim {

class Scene;

// A sensor whose reading is one number.
class SensorValueAccess {
 public:
  virtual ~SensorValueAccess() = default;
  // The last reading of `id` into *value: 0, or -1 if `id` is not a live
  // sensor of this module's type.
  virtual int ReadValue(const Scene& scene, ObjectId id, double* value) const noexcept = 0;
};

class LedAccess {
 public:
  virtual ~LedAccess() = default;
  // Sets LED `id` of robot `robot` (colour clamped to 0..1): 0, or -1 if
  // `id` is not a live LED of that robot.
  virtual int SetLed(Scene* scene, int robot, ObjectId id, const Vec3& color,
                     bool on) const noexcept = 0;
};

class IrAccess {
 public:
  virtual ~IrAccess() = default;
  // Queues `data` on transceiver `id` of robot `robot` (sim.sendIrMessage's
  // rules): 0, or -1 if `id` is not a live transceiver of that robot or
  // `size` is more than its payload_size.
  virtual int Send(Scene* scene, int robot, ObjectId id, const uint8_t* data,
                   size_t size) const noexcept = 0;
  // 1 if its message went out in the last sense phase, 0 if not, -1 if `id`
  // is not a live transceiver.
  virtual int Sent(const Scene& scene, ObjectId id) const noexcept = 0;
  // The messages it heard in the last sense phase into out[0..max) (bytes
  // point into its row: valid until the next sense phase); how many there
  // are, or -1 if `id` is not a live transceiver.
  virtual int Receive(const Scene& scene, ObjectId id, SwarmsimIrMessage* out,
                      int max) const noexcept = 0;
};

}  // namespace swarmsim
