// A narrow service: range-and-bearing boards for the plugins' C API
// (plugin_world_api.cc: set_range_and_bearing_data, read_range_and_bearing,
// ABI 7), which names no module. The range_and_bearing module's world
// instance (World::find_module("range_and_bearing")) implements it; without
// that module no object is a board.
#pragma once

#include <cstddef>
#include <cstdint>

#include "framework/handle.h"
#include "framework/plugin_api.h"

namespace swarmsim {

class Scene;

class RangeAndBearingAccess {
 public:
  virtual ~RangeAndBearingAccess() = default;
  // Sets what the board `id` of robot `robot` sends (sim.setRangeAndBearingData's
  // rules). 0, or -1 if `id` is not a live board of that robot or `size` is
  // more than its payload size. Never throws.
  virtual int SetData(Scene* scene, int robot, ObjectId id, const uint8_t* data,
                      size_t size) const noexcept = 0;
  // The board's readings of the last sense phase into out[0..max) (payloads
  // point into the board's row: valid until the next sense phase); how many
  // there are, or -1 if `id` is not a live board. Never throws.
  virtual int Read(const Scene& scene, ObjectId id, SwarmsimRangeAndBearingReading* out,
                   int max) const noexcept = 0;
};

}  // namespace swarmsim
