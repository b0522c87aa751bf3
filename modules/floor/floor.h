// The floor: what the ground under the robots looks like (issue 28), as a
// world file describes it in its `floor:` section (worlds/README.md): a
// background colour, a PNG image placed by its corners in the world, and
// shapes drawn over it in file order (circles, rectangles, linear and radial
// gradients: nests and zones). It is drawn once, when the world is loaded,
// into a raster that becomes the world's floor layer (framework/floor_layer.h),
// which ground sensors read and the recorder, the renderer (snapshots,
// video) and the viewer show.
//
// With paint (modules/paint) in the same world, the paint layer starts from
// this floor (each of its pixels takes the floor's colour at its centre) and
// becomes the world's floor layer in its place: trails are drawn on top of
// the floor, and ground sensors see both.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "framework/floor_layer.h"
#include "framework/math.h"
#include "framework/module.h"

namespace swarmsim {
class ModuleRegistry;
class World;
struct WorldSectionDescriptor;
}  // namespace swarmsim

namespace swarmsim::floors {

// The largest floor image file and floor raster, in pixels (64 megapixels:
// 192 MB of RGB).
inline constexpr int64_t kMaxFloorPixels = 64'000'000;

// One shape drawn on the floor. A pixel is drawn when its centre is inside.
struct FloorShape {
  enum class Kind { kCircle, kRectangle, kLinearGradient, kRadialGradient };
  Kind kind = Kind::kCircle;
  Vec3 a, b;             // circle, radial: a = centre; rectangle: a = min, b = max;
                         // linear: a = from, b = to (z unused)
  double radius = 0;     // m: circle, radial gradient
  Vec3 color, color2;    // RGB 0..1: the colour; a gradient's start and end
  bool bounded = false;  // linear gradient: drawn only within [lo, hi] (else everywhere)
  Vec3 lo, hi;
};

struct FloorSettings {
  double min_x = -1, min_y = -1, max_x = 1, max_y = 1;  // m, the area the raster covers
  double resolution = 0.01;                             // m, side of one pixel
  Vec3 background{1, 1, 1};                             // RGB 0..1
  // The image (none when empty): its pixels (rows from the top, RGB) and
  // where its corners lie in the world (m).
  int image_width = 0, image_height = 0;
  std::vector<uint8_t> image_rgb;
  double image_min_x = 0, image_min_y = 0, image_max_x = 0, image_max_y = 0;
  std::vector<FloorShape> shapes;  // drawn in order, over the image
};

// The floor drawn into a raster: the world's floor layer while it lives
// (unless a paint layer takes its place and starts from it).
class FloorRaster final : public Module, public FloorLayer {
 public:
  // Throws swarmsim::Error for a bad area or resolution, or a raster over
  // kMaxFloorPixels.
  FloorRaster(World* world, const FloorSettings& settings);
  ~FloorRaster() override;

  // Snapshots: drawn once when the world loads, never changed.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  FloorArea floor_area() const override { return area_; }
  std::span<const uint8_t> floor_rgb() const override { return rgb_; }
  // Drawn by the image or a shape, in a colour other than the background.
  bool floor_marked(int column, int row) const override {
    return marked_[static_cast<size_t>(row) * area_.width + column] != 0;
  }

 private:
  World* world_;
  FloorArea area_;
  std::vector<uint8_t> rgb_;     // (height x width x 3), row 0 the +y edge
  std::vector<uint8_t> marked_;  // (height x width)
};

// Reads a PNG floor image, refusing one over kMaxFloorPixels before decoding
// it. Throws swarmsim::Error naming the file (missing, not a PNG, too big).
void ReadFloorImage(const std::filesystem::path& path, FloorSettings* settings);

// The "floor" module (made by the `floor:` section with its FloorSettings).
void Register(ModuleRegistry* registry);
// The `floor:` world-file section; registered before paint's, so that the
// paint layer finds the floor to start from.
std::shared_ptr<const WorldSectionDescriptor> FloorSection();

}  // namespace swarmsim::floors
