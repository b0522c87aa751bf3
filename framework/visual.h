// What an object looks like: the one thing the recorder (swarm/record),
// the renderer (modules/rendering: snapshots, video, vision sensors) and
// the browser viewer (swarm/viewer/web) know of an object type's looks.
// A type declares it with its descriptor's `visual` hook (object_type.h),
// which fills an ObjectVisual from one of its rows; none of them names a
// type or a module.
//
// Static and changing parts: `kind`, `size` and `mesh` are read when a
// recording writes its scene (and again when the scene's structure
// changes); `color`, `on` and `hit` at every recorded step and every
// rendered frame. A hook runs for every object of its type at each of
// those, from several threads at once: it fills the struct from the row,
// nothing more (no allocation, no lookup by name).
#pragma once

#include <cstdint>

#include "framework/math.h"

namespace swarmsim {

class TriangleMesh;

enum class VisualKind : uint8_t {
  kNone,  // not drawn: the object is recorded only as a robot's root frame
  // Solids, centred on the object's frame, sized as a shape is
  // (worlds/README.md "shape"): the renderer and the viewer draw them lit.
  kBox,       // size: full extents x, y, z
  kCylinder,  // size: [radius, 0, height], axis along z
  kSphere,    // size: [radius, 0, 0]
  kCapsule,   // size: [radius, 0, height with the caps], axis along z
  kMesh,      // `mesh` (scale applied); size: extents of the box that holds it
  // A light (an LED): a sphere of radius size.x at the origin that glows in
  // `color` while `on` (a black one emits nothing), drawn dark otherwise.
  // Rendered images (vision sensors too) show it.
  kLight,
  // A marker, not a body: a segment from the origin along +z, size.x m
  // long, drawn to `hit` m when something is detected there. The viewer
  // draws it (its "rays" switch) in `color`, and so do snapshots and video
  // (a line; `swarmsim run --no-rays`: not); vision sensors do not see it.
  kRay,
};

// The recording's and the viewer's name of a kind ("box", ..., "light", "ray").
const char* ToString(VisualKind kind);
inline bool IsSolid(VisualKind kind) {
  return kind >= VisualKind::kBox && kind <= VisualKind::kMesh;
}

struct ObjectVisual {  // 72 bytes
  VisualKind kind = VisualKind::kNone;
  bool on = true;                      // kLight: switched on; others: true
  bool mesh_colors = false;            // kMesh: its per-triangle colours instead of `color`
  Vec3 size{};                         // m, as the kind says
  Vec3 color{1, 1, 1};                 // RGB 0..1: may change every step
  double hit = -1;                     // kRay: m from the origin to what it detects; < 0: nothing
  const TriangleMesh* mesh = nullptr;  // kMesh: the scene's asset (outlives the step)
};

}  // namespace swarmsim
