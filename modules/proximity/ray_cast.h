// Exact ray-primitive tests and the small geometric helpers the proximity
// module builds its indexes with. No OctoMap here: this file is testable on
// its own.
//
// Conventions. A ray is an origin, a unit direction and a length; a hit is
// the smallest t in [0, length] at which the ray is in the (closed) solid.
// A ray that starts inside or on a solid therefore hits it at t = 0: a sensor
// pushed into a wall reads "detected, distance 0" rather than seeing out of it.
#pragma once

#include <algorithm>
#include <cmath>
#include <compare>  // framework/handle.h uses operator<=> without including <compare>
#include <cstdint>
#include <utility>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/scene.h"

namespace swarmsim::proximity {

// Ray tests in the primitive's own frame (centred, cylinder axis = z).
// Each returns true and sets *t (0 <= *t <= max_t) for the nearest hit.
bool RayBox(const Vec3& o, const Vec3& d, const Vec3& half_size, double max_t, double* t);
bool RayCylinder(const Vec3& o, const Vec3& d, double radius, double half_height, double max_t,
                 double* t);
bool RaySphere(const Vec3& o, const Vec3& d, double radius, double max_t, double* t);

// A shape frozen at a world pose, ready for ray tests.
struct PlacedShape {  // 104 bytes
  Pose X_WS;          // pose of the shape in the world
  Pose X_SW;          // its inverse, for taking rays into the shape frame
  Vec3 half_size;  // box: half extents; cylinder: (radius, radius, half height); sphere: (r, r, r)
  ObjectId id;     // the shape's object
  int32_t instance;  // model instance (robot) or -1
  ShapeKind kind;
  // Mesh: the asset (kept alive by the scene, or by the static index), and
  // half_size is half its bounds' extents, centred at mesh->lo()..hi().
  const TriangleMesh* mesh = nullptr;
};

PlacedShape PlaceShape(const ShapeData& shape, const Pose& X_WS, ObjectId id, int instance);

// The nearest hit of the world ray (p_W, unit d_W, length max_t) on the shape.
bool RayCast(const PlacedShape& shape, const Vec3& p_W, const Vec3& d_W, double max_t, double* t);

// World axis-aligned bounding box of the shape.
void WorldBounds(const PlacedShape& shape, Vec3* lo, Vec3* hi);

// Radius about the shape origin's (x, y) that contains the shape's footprint
// in the world xy plane. ShapeData::BoundingRadius when the shape stands
// upright; the 3D bounding-sphere radius when it is tilted.
double WorldFootprintRadius(const ShapeData& shape, const Pose& X_WS);

// The same, remembering the one costly case (a tilted cylinder's hypot) in
// `memo` for a caller that asks about the same shape every step.
struct FootprintMemo {                // 24 bytes
  double size_x = NAN, size_z = NAN;  // the cylinder's size the radius is for
  double radius = 0;
};
double WorldFootprintRadius(const ShapeData& shape, const Pose& X_WS, FootprintMemo* memo);

// Conservative overlap: false only if the shape, grown by `margin`, misses
// the axis-aligned cube (centre, half edge `half`). Exact for boxes and
// spheres; for cylinders, the cube must touch both the cylinder's bounding
// box and a capsule around its axis.
bool MayOverlapCube(const PlacedShape& shape, const Vec3& centre, double half, double margin);

// A segment p + t v, t in [0, 1], for the broad phase of occlusion tests
// (blob cameras, range-and-bearing, light): its inverse direction is
// computed once, then each box costs a slab test.
struct Segment {
  double p[3], inv[3];  // inv: 1 / v per axis (inf for 0)
  Segment(const Vec3& from, const Vec3& v)
      : p{from.x, from.y, from.z}, inv{1 / v.x, 1 / v.y, 1 / v.z} {}
  // Does it meet the box [lo, hi]? (Along an axis it does not move on, it
  // must lie within the box's slab.)
  bool MeetsBox(const Vec3& lo, const Vec3& hi) const {
    double t0 = 0, t1 = 1;
    const double los[3] = {lo.x, lo.y, lo.z}, his[3] = {hi.x, hi.y, hi.z};
    for (int i = 0; i < 3; ++i) {
      if (std::isinf(inv[i])) {
        if (p[i] < los[i] || p[i] > his[i]) return false;
        continue;
      }
      double ta = (los[i] - p[i]) * inv[i], tb = (his[i] - p[i]) * inv[i];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    return true;
  }
};

}  // namespace swarmsim::proximity
