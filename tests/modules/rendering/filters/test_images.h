// Synthetic images for the filter tests (blobs_test.cc, filters_test.cc):
// a filled image, and ellipses drawn into one with what was drawn (pixel
// count, mean centre, box) to check the blob detector against.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "framework/image.h"

namespace swarmsim::testing {

inline Image Filled(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
  Image image;
  image.Resize(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = image.Pixel(x, y);
      p[0] = r, p[1] = g, p[2] = b;
    }
  return image;
}

// What the test drew of one shape: its pixels' count, mean centre and box.
struct Drawn {
  int pixels = 0;
  double x = 0, y = 0;  // mean pixel centre
  int min_x = 1 << 30, min_y = 1 << 30, max_x = -1, max_y = -1;
};

// An ellipse of semi-axes a (along angle `angle`, counter-clockwise with y
// up) and b, centred at (cx, cy) in pixels (y down), filled with `colour`.
inline Drawn DrawEllipse(Image* image, double cx, double cy, double a, double b, double angle,
                         const uint8_t colour[3]) {
  Drawn d;
  const double c = std::cos(angle), s = std::sin(angle);
  for (int y = 0; y < image->height; ++y)
    for (int x = 0; x < image->width; ++x) {
      const double dx = x + 0.5 - cx, dy_up = cy - (y + 0.5);
      const double along = dx * c + dy_up * s, across = -dx * s + dy_up * c;
      if (along * along / (a * a) + across * across / (b * b) > 1) continue;
      uint8_t* p = image->Pixel(x, y);
      p[0] = colour[0], p[1] = colour[1], p[2] = colour[2];
      ++d.pixels;
      d.x += x + 0.5;
      d.y += y + 0.5;
      d.min_x = std::min(d.min_x, x), d.max_x = std::max(d.max_x, x);
      d.min_y = std::min(d.min_y, y), d.max_y = std::max(d.max_y, y);
    }
  d.x /= d.pixels;
  d.y /= d.pixels;
  return d;
}

}  // namespace swarmsim::testing
