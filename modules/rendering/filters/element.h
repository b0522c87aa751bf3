// Inside the filters module: what one element of a chain sees while the
// chain runs (the work image, the source, the output being filled) and the
// element interface the registry's descriptors make (framework/vision_filter.h).
#pragma once

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

  void Swap() { std::swap(work, next); }
};

// Intensity of an RGB pixel, 0..255 (CoppeliaSim's: the mean of the channels).
inline uint8_t Intensity(const uint8_t* rgb) {
  return static_cast<uint8_t>((rgb[0] + rgb[1] + rgb[2] + 1) / 3);
}

// Blob detection on the mask `work` (blobs.cc): fills out->blobs and appends
// its packet.
void DetectBlobs(const FilterRun& run, int min_pixels, int max_blobs, FilterOutput* out);

}  // namespace filters

// One configured element of a chain: immutable, shared by every copy of the
// chain, so Apply is const and keeps nothing between runs.
class VisionFilterElement {
 public:
  virtual ~VisionFilterElement() = default;
  virtual void Apply(filters::FilterRun* run) const = 0;
};

}  // namespace swarmsim
