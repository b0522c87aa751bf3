// modules/ir_messaging: the IR transceiver (the Kilobot's messaging: an IR
// LED and a photodiode under the robot, talking through light reflected by
// the floor). A controller queues at most one message per transceiver per
// step; in the next sense phase each queued message gets a start time
// within the step; a sender that hears a transmission already on the air
// then (carrier sense) defers: nothing goes out. The others are on the air
// for `packet_time` from their start. A receiver hears every message sent
// from within its `range` (m, between the transceivers' origins; robots
// and walls do not block: the light goes through the floor) unless another
// message it can hear overlaps it in time (both lost there: the hidden-
// terminal collision), or it is lost; each message it hears comes with the
// sender's bytes and a noisy estimate of the distance. See module.cc for
// the exact rules, worlds/README.md (`ir_transceiver`) for the keys.
//
// Public: the rows (tests, benchmarks) and Register (one line in
// modules/builtin.cc). Code outside the module finds the type by name
// (kTypeName, Scene::FindType); the plugins' C API reaches it through
// framework/device_access.h's IrAccess.
#pragma once

#include <cstdint>
#include <vector>

#include "framework/handle.h"
#include "framework/shared_settings.h"

namespace swarmsim {
class ModuleRegistry;
}  // namespace swarmsim

namespace swarmsim::ir_messaging {

inline constexpr const char* kTypeName = "ir_transceiver";
// The largest payload a transceiver may declare (bytes): a Kilobot sends
// 12; more is a load error.
inline constexpr int64_t kMaxPayloadSize = 255;

// Settings: shared by the copies of one model entry (shared_settings.h).
// The defaults are the Kilobot's (sources in worlds/README.md).
struct IrSettings {
  double range = 0.10;             // m: a transceiver hears senders within it
  uint32_t payload_size = 12;      // bytes a message carries at most (kilolib's message_t)
  double packet_time = 0.004035;   // s a message is on the air (12 bytes x 10 bits x 33.6 us)
  double distance_noise = 0.002;   // m: std dev of Gaussian noise on the distance estimate
  double loss_probability = 0;     // 0..1: each message heard is lost
  double failure_probability = 0;  // 0..1: the transceiver hears nothing at a step
  bool carrier_sense = true;       // defer when a transmission is heard at the start time
  bool collisions = true;          // overlapping messages are lost at a receiver hearing both
};

// One message heard in the last sense phase.
struct IrReceived {          // 24 bytes
  double distance = 0;       // m, the estimate (noise added, >= 0)
  ObjectId sender;           // the sending transceiver (not given to controllers)
  uint32_t data_offset = 0;  // its bytes: received[data_offset, + data_size)
  uint32_t data_size = 0;
};

struct IrTransceiverRow {  // 104 bytes
  Shared<IrSettings> settings;
  // State (hashed). The message queued for the next sense phase (at most
  // payload_size bytes), if `queued`.
  std::vector<uint8_t> outgoing;
  bool queued = false;
  // Whether the message queued went out in the last sense phase.
  bool sent = false;
  // What it heard in the last sense phase, in arrival (start time) order,
  // the bytes concatenated in `received`.
  std::vector<IrReceived> inbox;
  std::vector<uint8_t> received;
};

// Registers the `ir_transceiver` type, its Lua area and its sense-phase
// module (every world).
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::ir_messaging
