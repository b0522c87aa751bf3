// Noise and failure on what a device reads or does (issue 28's noise
// models): every sensor and actuator that has noise keys uses these, so
// that a world's noise means the same everywhere and stays deterministic.
//
// Streams: a device's noise at one step is drawn from
// NoiseStream(seed, slot, step, purpose): a stream keyed by the world's
// seed, the device's object slot, the step and what the draws are for.
// Nothing depends on which worker sensed which robot, on the thread count
// or on row order, and there is no state to hash: the same world, seed and
// step give the same draws. A device with no noise keys draws nothing, so a
// world without noise keeps its results (and its golden hash) bit for bit.
//
// Keys (each type lists and documents its own, worlds/README.md): for one
// reading, `noise` (std dev of Gaussian noise, in the reading's units),
// `noise_uniform` (half width of uniform noise) and `failure_probability`
// (the device reads nothing this step: no hit, no message, zero), read
// with ReadNoise. A reading's value v becomes v + N(0, noise) + U(-u, u),
// clamped by the device to what it can read.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "framework/random.h"

namespace swarmsim {

class ObjectReader;

struct NoiseSettings {  // 24 bytes
  double gaussian = 0;  // std dev
  double uniform = 0;   // half width
  double failure = 0;   // probability of reading nothing, 0..1
  bool any() const { return gaussian > 0 || uniform > 0 || failure > 0; }
  bool perturbs() const { return gaussian > 0 || uniform > 0; }
};

// What a device's stream is for: each purpose its own stream, so that adding
// noise to one reading never moves another's draws. New devices add theirs.
enum class NoisePurpose : uint32_t {
  kProximity = 1,
  kRangeAndBearing = 2,
  kRangeAndBearingLoss = 3,
  kGround = 4,
  kLight = 5,
  kForce = 6,
  kWheels = 7,
  kBlobCamera = 8,
  kCapacity = 9,
  kIrTransmit = 10,  // an IR message's start time (the sender's stream)
  kIrReceive = 11,   // an IR receiver's failure, losses and distance noise
};

// The stream of one device (object slot) at one step for one purpose. Slots
// below 2^26 and steps below 2^32 give distinct streams; robot streams
// (World's per-robot Rng) are small numbers and never meet these.
inline Rng NoiseStream(uint64_t seed, uint32_t slot, int64_t step, NoisePurpose purpose) {
  return Rng(seed, (uint64_t{static_cast<uint32_t>(purpose)} << 58) ^
                       ((uint64_t{slot} & 0x3FFFFFF) << 32) ^
                       (static_cast<uint64_t>(step) & 0xFFFFFFFFu));
}

// v + N(0, gaussian) + U(-uniform, uniform); draws only what is set.
inline double Perturb(const NoiseSettings& n, double v, Rng& rng) {
  if (n.gaussian > 0) v += rng.Normal(0, n.gaussian);
  if (n.uniform > 0) v += rng.Uniform(-n.uniform, n.uniform);
  return v;
}

// True (the device reads nothing this step) with probability `failure`;
// draws only when failure > 0.
inline bool Fails(const NoiseSettings& n, Rng& rng) {
  return n.failure > 0 && rng.Uniform() < n.failure;
}

// Reads `<prefix>noise`, `<prefix>noise_uniform` and `<prefix>failure_probability`
// (prefix "" for a one-reading device; "range_" for a reading among
// several). `max` bounds the two noise widths (in the reading's units);
// the probability is 0..1. Keys absent leave *out as it is
// (sensor_noise.cc).
void ReadNoise(const ObjectReader& r, std::string_view prefix, double max, NoiseSettings* out);

}  // namespace swarmsim
