// Deterministic random streams.
//
// Each robot gets its own stream keyed by (world seed, robot index), so
// results never depend on which worker ran which robot. The generator is
// xoshiro256** (Blackman & Vigna) seeded through splitmix64: 32 bytes of state
// per robot, where std::mt19937_64 would cost 2.5 KB.
#pragma once

#include <cstdint>

namespace swarmsim {

class Rng {  // 32 bytes
 public:
  Rng() : Rng(0, 0) {}
  // Stream `stream` of `seed`. Different (seed, stream) pairs are independent.
  Rng(uint64_t seed, uint64_t stream);

  uint64_t NextU64();
  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(NextU64() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [lo, hi] (inclusive).
  int64_t UniformInt(int64_t lo, int64_t hi);
  // Standard normal (Box-Muller; uses two uniforms, no cached spare: keeps the state small).
  double Normal(double mean, double stddev);

  const uint64_t* state() const { return s_; }

 private:
  uint64_t s_[4];
};

}  // namespace swarmsim
