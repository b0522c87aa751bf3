// What the renderer draws, as world-frame triangles with normals and
// colours (no OpenGL here): one item per object whose type declares a solid
// or a light visual (framework/visual.h: shapes, LEDs, ...), per environment
// box, and the floor. Built from the scene each time a frame or a sense step needs it;
// items keep the scene's slot order, so the same scene gives the same arrays.
#pragma once

#include <cstdint>
#include <vector>

#include "framework/image.h"
#include "framework/math.h"
#include "modules/rendering/render.h"

namespace swarmsim {
class World;
}

namespace swarmsim::rendering {

inline constexpr uint32_t kNoSlot = UINT32_MAX;

struct DrawItem {
  uint32_t slot;    // the object's slot, or kNoSlot (environment, floor)
  uint32_t first;   // first vertex in DrawList's arrays
  uint32_t count;   // vertices (3 per triangle)
  float center[3];  // bounding sphere, world frame
  float radius;
  bool emissive;  // drawn in its colour without lighting (LEDs)
};

struct LightSource {
  enum Kind : uint8_t { kDirectional, kPoint, kSpot } kind = kDirectional;
  Vec3 position;                      // world frame (point, spot)
  Vec3 direction{0, 0, -1};           // world frame, where the light goes (directional, spot)
  Vec3 color{1, 1, 1};                // RGB 0..1
  double cutoff = 0.5;                // rad, spot half-angle
  double exponent = 0;                // spot: intensity falls off as cos^exponent
  double attenuation[3] = {1, 0, 0};  // constant, linear, quadratic (point, spot)
};

struct FloorLayer {
  bool present = false;  // a paint layer to lay on the floor
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  int width = 0, height = 0;
  const uint8_t* rgb = nullptr;  // row 0 at max_y (the paint module's layout)
};

struct DrawList {
  std::vector<float> xyz;     // 3 per vertex
  std::vector<float> normal;  // 3 per vertex
  std::vector<uint8_t> rgb;   // 3 per vertex
  std::vector<DrawItem> items;
  std::vector<LightSource> lights;  // on, in scene order (at most 8 are used)
  bool scene_has_lights = false;    // light objects exist (on or off)
  FloorLayer floor;
  // Ray visuals (proximity sensors' rays) as line segments, 2 vertices
  // each, when BuildDrawList is asked for them (snapshots and video; never
  // a vision sensor's image: markers are not bodies).
  std::vector<float> ray_xyz;    // 6 per ray
  std::vector<uint8_t> ray_rgb;  // 6 per ray
  int64_t step = -1;             // the world's step when built (the paint layer's version)
  Vec3 lo, hi;                   // bounds of the shapes and the environment (zero when none)
  bool has_bounds = false;       // lo, hi hold something
};

// Fills *list from `world`'s scene. `segments`: sides of a cylinder and
// slices of a sphere; lights (LEDs) are drawn at least `min_led_radius` m
// big (an overview keeps them visible). Ray visuals are markers, drawn as
// lines only with `rays` (from the object's origin along its +z axis, to
// what it detects or its full length, in its colour).
void BuildDrawList(const World& world, int segments, DrawList* list, double min_led_radius = 0,
                   bool rays = false);

struct DrawOptions {
  const std::vector<uint8_t>* visible = nullptr;  // by slot: 1 drawn (null: every slot)
  bool floor = true;                              // the floor and its paint
  Vec3 background{0.80, 0.85, 0.90};              // RGB where nothing is drawn
};

// Draws `list` as `view` sees it into *image (render.cc, OSMesa).
void Draw(const DrawList& list, const View& view, const DrawOptions& options, Image* image);

}  // namespace swarmsim::rendering
