// modules/range_and_bearing: the range-and-bearing board (ARGoS's
// range_and_bearing actuator and sensor on the foot-bot and the e-puck): an
// emitter and receiver hung on a robot. Every step each board sends the
// bytes its robot last set (kept until changed); in the sense phase every
// board hears the boards of other robots within its own range, each
// reading the payload, the distance and the direction of the sender in the
// receiver board's own frame; occluded by static shapes and the map (the
// world's line of sight) and, as a setting, by other robots' bodies; lost
// with a probability that may grow with distance; with Gaussian noise on
// range and bearing; at most `capacity` readings per step.
//
// Public: the rows (tests, the Python arrays, the recorder's links read
// them) and Register (one line in modules/builtin.cc). Code outside the
// module finds the type by name (kTypeName, Scene::FindType) and reads
// scene.rows<RangeAndBearingRow>(type).
#pragma once

#include <cstdint>
#include <vector>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/sensor_noise.h"
#include "framework/shared_settings.h"

namespace swarmsim {
class ModuleRegistry;
class Scene;
}  // namespace swarmsim

namespace swarmsim::range_and_bearing {

inline constexpr const char* kTypeName = "range_and_bearing";
// The largest payload a board may declare (bytes): a real board sends a few
// (foot-bot 10, e-puck 4); more is a load error.
inline constexpr int64_t kMaxPayloadSize = 1024;

enum class CapacityOrder : uint8_t {
  kNearest,  // the `capacity` nearest senders are kept
  kRandom,   // `capacity` senders drawn at random (uniformly, without replacement)
};

// Settings: shared by the copies of one model entry (shared_settings.h).
struct RangeAndBearingSettings {
  double range = 3;            // m: a board hears the senders within it
  uint32_t payload_size = 10;  // bytes a board sends every step
  uint32_t capacity = 0;       // readings kept per step at most; 0: all
  CapacityOrder capacity_order = CapacityOrder::kNearest;
  double loss_probability = 0;   // p0: every message is lost with p0 + ...
  double loss_at_range = 0;      // ... + p1 (d / range)^2 (clamped to 1)
  NoiseSettings range_noise;     // m (failure: the whole board hears nothing)
  NoiseSettings bearing_noise;   // rad, on bearing and elevation
  bool occlusion = true;         // static shapes and the map block
  bool robot_occlusion = false;  // other robots' shapes block too
  // The probability that a message from d metres away is lost.
  double LossAt(double d) const {
    if (loss_at_range <= 0) return loss_probability;
    const double f = d / range;
    const double p = loss_probability + loss_at_range * f * f;
    return p < 1 ? p : 1;
  }
};

// One message heard in the last sense phase, in the receiver board's frame
// (its +x the bearing 0, +z up).
struct RangeAndBearingReading {  // 40 bytes
  double range = 0;          // m, from the receiver board's origin to the sender's (noise added)
  double bearing = 0;        // rad, in (-pi, pi]: about +z from +x, counter-clockwise
  double elevation = 0;      // rad, in [-pi/2, pi/2]: above the board's xy plane
  ObjectId sender;           // the sending board (not given to scripts: ARGoS gives no identity)
  uint32_t data_offset = 0;  // its payload: received[data_offset, + data_size)
  uint32_t data_size = 0;
};

struct RangeAndBearingRow {  // 80 bytes
  Shared<RangeAndBearingSettings> settings;
  // State (hashed). What this board sends (at most payload_size bytes; the
  // message is padded with zeros to payload_size), kept until changed.
  std::vector<uint8_t> data;
  // What it heard in the last sense phase: nearest first (by the noiseless
  // distance, then the sender's handle), payloads concatenated in `received`.
  std::vector<RangeAndBearingReading> readings;
  std::vector<uint8_t> received;
};

// Registers the `range_and_bearing` type, its Lua area and its sense-phase
// module (every world).
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::range_and_bearing
