// A narrow service: what a proximity sensor read in the last sense phase,
// for the plugins' C API (plugin_world_api.cc: read_proximity_sensor(s)),
// which names no module. World holds one (World::proximity_readings()) that
// the proximity module provides when it starts; without a provider no
// object is a proximity sensor.
#pragma once

#include "framework/handle.h"

namespace swarmsim {

class Scene;

class ProximityReadings {
 public:
  virtual ~ProximityReadings() = default;
  // 1 and *distance (m) if the proximity sensor `id` detected something, 0
  // if it detected nothing, -1 if `id` is not a live proximity sensor.
  // Never throws (called from C); thread-safe (reads only).
  virtual int Read(const Scene& scene, ObjectId id, double* distance) const noexcept = 0;
};

}  // namespace swarmsim
