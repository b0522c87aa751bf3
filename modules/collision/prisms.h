// Exact distances between vertical prisms: upright cylinders (axis along
// world z) and boxes turned only about z, the shapes of most swarm robots,
// walls and pillars. Their Minkowski difference is a 2D convex shape times a
// z interval, so the distance is sqrt(d_xy^2 + d_z^2): closed form, where
// GJK converges slowly on curved shapes. No FCL here (tested on its own).
#pragma once

#include "framework/math.h"

namespace swarmsim::collision {

struct Prism {
  enum Kind : unsigned char { kNone, kCircle, kRect } kind = kNone;
  double cx = 0, cy = 0;  // centre in the plane
  double c = 1, s = 0;    // the rectangle's heading (cos, sin)
  double hx = 0, hy = 0;  // half extents (rectangle) or radius (hx, circle)
  double z0 = 0, z1 = 0;  // the z interval
  bool exact = true;      // the shape itself, else a prism around it (a lower bound)
};

// The prism of a box (full extents `size`) or cylinder (`radius`, `height`)
// at pose X, or kind kNone when its axis is not vertical.
Prism BoxPrism(const Pose& X, const Vec3& size);
Prism CylinderPrism(const Pose& X, double radius, double height);
// A rectangle prism around a cylinder lying on its side (axis horizontal, a
// wheel): not exact, its distances are lower bounds. kNone otherwise.
Prism LyingCylinderBound(const Pose& X, double radius, double height);

// The distance between two prisms and the closest points (world), when the
// closed form applies: false when they touch or their footprints overlap
// (the caller measures those otherwise).
bool PrismDistance(const Prism& a, const Prism& b, double* d, Vec3* pa, Vec3* pb);

}  // namespace swarmsim::collision
