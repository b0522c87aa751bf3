// The floor image: a raster of the floor some module keeps (the floor,
// modules/floor, or the paint layer, modules/paint, which starts from the
// floor when there is one), read by those that show or sense the floor (the
// recorder, the renderer, ground sensors) without knowing which module it is.
// World holds at most one (World::floor_layer); its provider sets it when it
// is made and lives as long as the world.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>

#include "framework/math.h"

namespace swarmsim {

// Image: row 0 is the area's +y edge (north up), column 0 its -x edge; pixel
// (c, r) covers x in min_x + [c, c + 1) res and y in max_y - [r + 1, r) res.
struct FloorArea {
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // m, the floor area covered
  double resolution = 0;                              // m, side of one pixel
  int width = 0, height = 0;                          // pixels
  Vec3 background;                                    // RGB in [0, 1], the bare floor
};

class FloorLayer {
 public:
  virtual ~FloorLayer() = default;
  virtual FloorArea floor_area() const = 0;
  // (height x width x 3) RGB bytes, row 0 first.
  virtual std::span<const uint8_t> floor_rgb() const = 0;
  // Whether the pixel was ever marked (else it shows the background).
  virtual bool floor_marked(int column, int row) const = 0;
};

// The pixel of `a` under the point (x, y) m: row * width + column, or -1
// outside the area (where the floor is the background).
inline int64_t FloorPixelAt(const FloorArea& a, double x, double y) {
  const double c = std::floor((x - a.min_x) / a.resolution);
  const double r = std::floor((a.max_y - y) / a.resolution);
  if (!(c >= 0 && r >= 0 && c < a.width && r < a.height)) return -1;
  return static_cast<int64_t>(r) * a.width + static_cast<int64_t>(c);
}

}  // namespace swarmsim
