// Inside the filters module: what one element of a chain sees while the
// chain runs (the work image, the source, the output being filled) and the
// element interface the registry's descriptors make (framework/vision_filter.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "framework/plugin_api.h"
#include "framework/vision_filter.h"
#include "modules/rendering/filters/filters.h"

namespace swarmsim {

namespace filters {

// The image passed from element to element. Its layout is its kind's:
// colour 3 bytes a pixel, grey and mask 1 (a mask holds 0 or 255), depth a
// float a pixel; rows top to bottom.
struct WorkImage {
  int width = 0, height = 0;
  uint32_t kind = kSwarmsimColourImage;  // one SwarmsimImageKind (never values)
  std::vector<uint8_t> pixels;
  std::vector<float> depth;

  size_t count() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
  // Sizes the buffer for `kind` (contents unspecified).
  void Reset(int w, int h, uint32_t k) {
    width = w, height = h, kind = k;
    if (k == kSwarmsimDepthImage) {
      depth.resize(count());
    } else {
      pixels.resize(count() * (k == kSwarmsimColourImage ? 3 : 1));
    }
  }
};

// One run of a chain: elements read `work`, write their result into `next`
// and call Swap (buffers are reused), and append to `out`.
struct FilterRun {
  const Image* source = nullptr;
  const CameraModel* camera = nullptr;
  FilterOutput* out = nullptr;
  WorkImage work;
  WorkImage next;
  size_t packets = 1;  // packets of `out` written so far (1: the statistics)

  void Swap() { std::swap(work, next); }
  // The next packet of `out`, empty (its buffer reused from the last run).
  std::vector<double>& NewPacket() {
    if (packets == out->packets.size()) out->packets.emplace_back();
    std::vector<double>& packet = out->packets[packets++];
    packet.clear();
    return packet;
  }
};

// From image positions to the sensor's frame (swarmsim's, modules/rendering/
// render.h): x along the view axis, z up in the image, y to the image's left.
struct Projection {
  double half_width, half_height;
  double pitch;  // m per pixel at depth 1 (perspective) or at any depth (orthographic)
  bool perspective;

  Projection(const CameraModel& camera, int width, int height)
      : half_width(width / 2.0), half_height(height / 2.0), perspective(camera.perspective) {
    const double larger = std::max(width, height);
    pitch = perspective ? 2 * std::tan(camera.fov / 2) / larger : camera.ortho_size / larger;
  }
  // The point at `depth` (m along the view axis) seen at (x, y), pixels
  // from the top-left corner (a pixel's centre at + 0.5).
  Vec3 Point(double x, double y, double depth) const {
    const double scale = perspective ? pitch * depth : pitch;
    return {depth, -(x - half_width) * scale, (half_height - y) * scale};
  }
};

// Intensity of an RGB pixel, 0..255 (CoppeliaSim's: the mean of the channels).
inline uint8_t Intensity(const uint8_t* rgb) {
  return static_cast<uint8_t>((rgb[0] + rgb[1] + rgb[2] + 1) / 3);
}

// Blob detection on the mask `work` (blobs.cc): fills out->blobs and appends
// its packet.
void DetectBlobs(FilterRun* run, int min_pixels, int max_blobs);

}  // namespace filters

// One configured element of a chain: immutable, shared by every copy of the
// chain, so Apply is const and keeps nothing between runs.
class VisionFilterElement {
 public:
  virtual ~VisionFilterElement() = default;
  virtual void Apply(filters::FilterRun* run) const = 0;
};

}  // namespace swarmsim
