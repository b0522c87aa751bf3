// Vision-sensor filter chains (CoppeliaSim's filter blocks, paper §2.1): a
// list of elements a sensor's model entry composes,
//
//   filters:
//     - {type: hsv_threshold, hue: [100, 140], saturation: [0.5, 1], value: [0.3, 1]}
//     - {type: blobs, min_pixels: 4}
//
// run on each image the sensor takes. As in CoppeliaSim, the chain passes a
// "work image" from element to element and collects value packets: packet 1
// is always the 15 statistics of the sensor's image (min, max and mean of
// intensity, red, green, blue and depth), then one packet per element that
// outputs values (blobs, point_cloud, a plugin's). Every element declares the
// kinds it takes and gives (colour, grey, mask, depth, values); a chain whose
// kinds do not fit is an error at the element's file:line:column. The
// elements are registered in the ModuleRegistry (framework/vision_filter.h):
// the built-in ones below by Register, a plugin's through plugin_api.h.
// worlds/README.md ("vision sensor filters") lists every element and key.
#pragma once

#include <array>
#include <memory>
#include <string_view>
#include <vector>

#include "framework/image.h"
#include "framework/math.h"

namespace swarmsim {

class ModuleRegistry;
class ObjectReader;

namespace filters {

// What a chain needs of the camera that took the image (point_cloud, the
// depth statistics). The resolution is the image's own.
struct CameraModel {
  bool perspective = true;
  double fov = M_PI / 3;    // rad, perspective: view angle of the image's larger side
  double ortho_size = 1.0;  // m, orthographic: extent of the image's larger side
  double near = 0.01;       // m, clipping planes: depth is measured along the view axis
  double far = 10.0;        // m
};

// One blob (a connected part of a mask, 8-connected).
struct Blob {
  int pixels = 0;                  // pixel count
  std::array<double, 3> colour{};  // mean RGB (0..1) of the source image over the blob
  double x = 0, y = 0;             // centroid, pixels from the top-left corner (y down)
  double u = 0, v = 0;             // centroid 0..1 as CoppeliaSim: from the bottom left, v up
  int min_x = 0, min_y = 0;        // bounding box, pixels, inclusive (y down)
  int max_x = 0, max_y = 0;        //
  double orientation = 0;          // rad, principal axis from the image's +x, counter-clockwise
                                   // (v up), in (-pi/2, pi/2]; 0 for a round blob
};

struct FilterOutput {
  Image image;  // the final work image as RGB (grey and masks in grey levels; no depth)
  std::vector<std::vector<double>> packets;  // packet 1: the 15 statistics; then per element
  std::vector<Blob> blobs;                   // of the last blobs element, largest first
  std::vector<Vec3> points;                  // m, point_cloud's, in the sensor's frame
  bool triggered = false;                    // an element triggered (a blob, a point)
};

struct ChainData;  // the elements, immutable (filters.cc)

// A parsed chain: cheap to copy (the elements are shared, immutable), and
// Run is const and keeps no state, so one chain may run on many threads.
class FilterChain {
 public:
  FilterChain();
  // Runs the chain on `image` (its depth, if any, for the depth elements and
  // statistics; a depth of another size counts as none). Throws
  // swarmsim::Error if a plugin's element fails.
  FilterOutput Run(const Image& image, const CameraModel& camera) const;
  // The same into *out, reusing its buffers (a sensor's reading). Without
  // `statistics`, packet 1 is left empty: a sensor whose packets may go
  // unread computes it when read (ImageStatistics; 3 us at 64x48).
  void Run(const Image& image, const CameraModel& camera, FilterOutput* out,
           bool statistics = true) const;
  size_t size() const;
  bool empty() const { return size() == 0; }
  // Whether an element reads depth (the sensor must render it).
  bool needs_depth() const;

 private:
  friend FilterChain ParseFilterChain(const ObjectReader&, std::string_view, const ModuleRegistry*);
  std::shared_ptr<const ChainData> data_;
};

// The chain the list at `key` of a model entry describes (none: an empty
// chain). Elements are looked up in `registry` (null, or one without
// elements: the built-in ones). Throws swarmsim::Error at the item's file:line:column for an
// unknown element (with a suggestion), a key it does not take, a bad value,
// or kinds that do not fit.
FilterChain ParseFilterChain(const ObjectReader& reader, std::string_view key,
                             const ModuleRegistry* registry);

// The point at `depth` (m along the view axis) that a camera of `width` x
// `height` pixels sees at image position (x, y) (pixels from the top-left
// corner, y down; a blob's centroid), in the sensor's frame as point_cloud
// gives it: x along the view axis, z up in the image, y to the image's left.
// A blob's bearing: atan2(p.y, p.x) of the point at depth 1.
Vec3 ImageToSensor(const CameraModel& camera, int width, int height, double x, double y,
                   double depth);

// Packet 1 alone (what Run puts first): CoppeliaSim's 15 statistics of
// `image`.
std::vector<double> ImageStatistics(const Image& image, const CameraModel& camera);

// Registers the built-in elements (modules/builtin.cc).
void Register(ModuleRegistry* registry);

}  // namespace filters
}  // namespace swarmsim
