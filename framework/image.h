// An image as cameras, vision sensors, filters and the video writer pass it:
// RGB bytes, row 0 at the top, and optionally a depth per pixel. No
// third-party types (modules/rendering draws into it with OSMesa).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace swarmsim {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;  // width * height * 3, rows top to bottom
  std::vector<float> depth;  // width * height metres along the view axis, or empty

  void Resize(int w, int h) {
    width = w;
    height = h;
    rgb.assign(static_cast<size_t>(w) * static_cast<size_t>(h) * 3, 0);
  }
  const uint8_t* Pixel(int x, int y) const {
    return rgb.data() + (static_cast<size_t>(y) * static_cast<size_t>(width) + x) * 3;
  }
  uint8_t* Pixel(int x, int y) {
    return rgb.data() + (static_cast<size_t>(y) * static_cast<size_t>(width) + x) * 3;
  }
};

}  // namespace swarmsim
