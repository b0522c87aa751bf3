// Paint nozzles (the paper's paint nozzle): an object that marks the floor
// under it in the paint layer (modules/paint) each step while enabled.
#pragma once

#include "framework/math.h"

namespace swarmsim {

struct PaintNozzleData {      // 40 bytes
  Vec3 color{0.1, 0.1, 0.8};  // RGB in [0, 1]
  double radius = 0.02;       // m, of the painted disc
  bool enabled = true;
};

}  // namespace swarmsim
