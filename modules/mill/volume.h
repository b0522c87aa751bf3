// The cutting volumes of mills (V-REP's mills, paper §2.1): convex volumes
// in the mill's frame M, pointing along +z like a proximity sensor's, with
// an exact point-in-volume test (a voxel goes when its centre is inside),
// a tight bounding box and the exact volume (for tests and messages).
//
// The volumes (R = range, a = half-angle):
// - cylinder: x^2 + y^2 <= radius^2, 0 <= z <= R (an end mill, a drill);
// - box:      |x| <= width / 2, |y| <= height / 2, 0 <= z <= R;
// - pyramid:  apex at the origin, 0 <= z <= R, |x| <= (width / 2) z / R,
//             |y| <= (height / 2) z / R (width x height at z = R);
// - cone:     a spherical sector: |p| <= R and the angle from +z <= a (< 90 deg);
// - disc:     a flat sector (a saw blade): |x| <= thickness / 2, y^2 + z^2 <= R^2,
//             the angle of (y, z) from +z <= a (<= 90 deg).
//
// Header-only: the module's cuts and the tests use the same code.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "framework/math.h"

namespace swarmsim::mill {

enum class VolumeKind : uint8_t { kCone, kCylinder, kPyramid, kDisc, kBox };

inline const char* ToString(VolumeKind kind) {
  switch (kind) {
    case VolumeKind::kCone: return "cone";
    case VolumeKind::kCylinder: return "cylinder";
    case VolumeKind::kPyramid: return "pyramid";
    case VolumeKind::kDisc: return "disc";
    case VolumeKind::kBox: return "box";
  }
  return "?";
}

// 64 bytes: one per mill row.
struct Volume {
  VolumeKind kind = VolumeKind::kCylinder;
  double range = 0.05;                          // m, along +z (cone, disc: from the origin)
  double angle = 30 * 3.141592653589793 / 180;  // rad, half-angle: cone (< pi/2), disc (<= pi/2)
  double radius = 0.01;                         // m, cylinder
  double width = 0.02, height = 0.02;           // m, along x and y: box, pyramid (at z = range)
  double thickness = 0.005;                     // m, disc, along x
};

// Is p (mill frame) inside the volume? Points on the boundary are inside.
inline bool Contains(const Volume& v, const Vec3& p) {
  if (!(p.z >= 0)) return false;  // every volume lies in z >= 0 (and NaN is outside)
  switch (v.kind) {
    case VolumeKind::kCylinder:
      return p.z <= v.range && p.x * p.x + p.y * p.y <= v.radius * v.radius;
    case VolumeKind::kBox:
      return p.z <= v.range && std::abs(p.x) <= v.width / 2 && std::abs(p.y) <= v.height / 2;
    case VolumeKind::kPyramid:
      return p.z <= v.range && std::abs(p.x) * v.range <= v.width / 2 * p.z &&
             std::abs(p.y) * v.range <= v.height / 2 * p.z;
    case VolumeKind::kCone: {
      if (p.SquaredNorm() > v.range * v.range) return false;
      const double rho = std::sqrt(p.x * p.x + p.y * p.y);
      return rho * std::cos(v.angle) <= p.z * std::sin(v.angle);
    }
    case VolumeKind::kDisc:
      return std::abs(p.x) <= v.thickness / 2 && p.y * p.y + p.z * p.z <= v.range * v.range &&
             std::abs(p.y) * std::cos(v.angle) <= p.z * std::sin(v.angle);
  }
  return false;
}

// The smallest box (mill frame) holding the volume.
inline void Bounds(const Volume& v, Vec3* lo, Vec3* hi) {
  switch (v.kind) {
    case VolumeKind::kCylinder:
      *lo = {-v.radius, -v.radius, 0};
      *hi = {v.radius, v.radius, v.range};
      return;
    case VolumeKind::kBox:
    case VolumeKind::kPyramid:
      *lo = {-v.width / 2, -v.height / 2, 0};
      *hi = {v.width / 2, v.height / 2, v.range};
      return;
    case VolumeKind::kCone: {
      const double r = v.range * std::sin(v.angle);
      *lo = {-r, -r, 0};
      *hi = {r, r, v.range};
      return;
    }
    case VolumeKind::kDisc: {
      const double r = v.range * std::sin(v.angle);
      *lo = {-v.thickness / 2, -r, 0};
      *hi = {v.thickness / 2, r, v.range};
      return;
    }
  }
}

// The volume's exact size, m^3.
inline double ExactVolume(const Volume& v) {
  constexpr double kPi = 3.141592653589793;
  switch (v.kind) {
    case VolumeKind::kCylinder: return kPi * v.radius * v.radius * v.range;
    case VolumeKind::kBox: return v.width * v.height * v.range;
    case VolumeKind::kPyramid: return v.width * v.height * v.range / 3;
    case VolumeKind::kCone:
      return 2 * kPi / 3 * v.range * v.range * v.range * (1 - std::cos(v.angle));
    case VolumeKind::kDisc: return v.thickness * v.angle * v.range * v.range;
  }
  return 0;
}

// The world-frame box holding the volume of a mill at pose X_WM.
inline void WorldBounds(const Volume& v, const Pose& X_WM, Vec3* lo, Vec3* hi) {
  Vec3 l, h;
  Bounds(v, &l, &h);
  *lo = {INFINITY, INFINITY, INFINITY};
  *hi = {-INFINITY, -INFINITY, -INFINITY};
  for (int c = 0; c < 8; ++c) {
    const Vec3 p = X_WM * Vec3{c & 1 ? h.x : l.x, c & 2 ? h.y : l.y, c & 4 ? h.z : l.z};
    *lo = {std::min(lo->x, p.x), std::min(lo->y, p.y), std::min(lo->z, p.z)};
    *hi = {std::max(hi->x, p.x), std::max(hi->y, p.y), std::max(hi->z, p.z)};
  }
}

}  // namespace swarmsim::mill
