// The rendering module's object types (objects.cc): cameras (viewpoints for
// snapshots and video), vision sensors (the paper's rendering sensors:
// images each sense step, through a filter chain) and lights. Internal to
// modules/rendering.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "framework/image.h"
#include "framework/math.h"
#include "modules/rendering/filters/filters.h"
#include "modules/rendering/geometry.h"

namespace swarmsim {
class ModuleRegistry;
class Scene;
}  // namespace swarmsim

namespace swarmsim::rendering {

inline constexpr char kModuleName[] = "rendering";

// What a camera or vision sensor sees: the frame is the object's (looks
// along +x, +z up: render.h).
struct Lens {
  bool orthographic = false;
  double fov = 1.0471975511965976;  // rad, horizontal
  double ortho_width = 1;           // m
  double near = 0.01, far = 10;     // m
  int width = 64, height = 48;      // pixels
};

struct CameraRow {
  Lens lens{false, 1.0471975511965976, 1, 0.05, 50, 640, 480};
};

struct VisionSensorRow {
  // Settings.
  Lens lens;
  bool depth = true;               // fill the depth buffer too
  double rate = 0;                 // Hz; 0: every step
  std::string detectable;          // entity path: what it sees (empty: everything)
  std::string where;               // "file:line:column" of `detectable`
  Vec3 background{0.0, 0.0, 0.0};  // RGB where nothing is seen
  bool floor = true;               // the floor (and its paint) is seen
  filters::FilterChain filters;    // run on each image (shared by copies)
  // The reading, updated when the sensor renders.
  Image image;
  filters::FilterOutput output;  // the chain's, when it has elements
  int64_t rendered_step = -1;    // the step it last rendered (-1: never)
};

struct LightRow {
  LightSource::Kind kind = LightSource::kDirectional;
  Vec3 color{1, 1, 1};
  bool on = true;
  double cutoff = 0.5235987755982988;  // rad, spot half-angle
  double exponent = 2;                 // spot fall-off
  double range = 0;                    // m, point and spot: half intensity here (0: no fall-off)
};

// What a filter chain needs to know of a sensor's lens.
filters::CameraModel CameraModelOf(const Lens& lens);

// Registers the types and the module.
void RegisterObjects(ModuleRegistry* registry);

// The lights that are on, in scene order, and whether the scene has any.
void CollectLights(const Scene& scene, std::vector<LightSource>* lights, bool* any);

}  // namespace swarmsim::rendering
