// The rendering module's public view of vision sensors' readings, for code
// outside the module (the Python arrays): the last image each one rendered,
// without the module's own types.
#pragma once

#include <cstdint>

#include "framework/image.h"

namespace swarmsim {
class Scene;
}  // namespace swarmsim

namespace swarmsim::rendering {

struct VisionReading {
  int width = 0, height = 0;        // pixels: the lens's resolution
  bool depth = false;               // the sensor keeps a depth image (`depth: true`)
  const Image* image = nullptr;     // what the camera saw (null before it first rendered)
  const Image* filtered = nullptr;  // its filter chain's image (null: no chain, or none yet)
  int64_t rendered_step = -1;       // the step it last rendered in (-1: never)
};

// The reading of the vision sensor at `slot`; false when that object is not
// a vision sensor (or the scene has none).
bool ReadVisionSensor(const Scene& scene, uint32_t slot, VisionReading* out);

}  // namespace swarmsim::rendering
