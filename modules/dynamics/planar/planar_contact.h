// Exact plane contact between circles and oriented rectangles, for the
// planar backend: penetration depth and the direction that separates A from
// B. Inline (the Jacobi passes call it for every candidate pair).
#pragma once

#include <algorithm>
#include <cmath>

namespace swarmsim::planar {

// A circle (radius hx, `box` false) or a rectangle of half extents (hx, hy)
// turned by (c, s) = (cos, sin) of its yaw, centred at (x, y). Metres.
struct PlaneShape {  // 56 bytes
  double x = 0, y = 0;
  double c = 1, s = 0;
  double hx = 0, hy = 0;
  bool box = false;
};

// A contact: A must move by depth * (n_x, n_y) (unit) to separate from B.
// depth <= 0: apart (or touching).
struct PlaneContact {
  double depth = 0;
  double n_x = 0, n_y = 0;
};

namespace detail {

// Circle (px, py, r) against rectangle b.
inline PlaneContact CircleBox(double px, double py, double r, const PlaneShape& b) {
  // Centre in b's frame.
  const double dx = px - b.x, dy = py - b.y;
  const double lx = b.c * dx + b.s * dy, ly = -b.s * dx + b.c * dy;
  const double qx = std::clamp(lx, -b.hx, b.hx), qy = std::clamp(ly, -b.hy, b.hy);
  PlaneContact contact;
  double nx, ny;
  if (qx != lx || qy != ly) {  // centre outside: nearest point on the boundary
    const double ex = lx - qx, ey = ly - qy;
    const double d2 = ex * ex + ey * ey;
    if (d2 >= r * r) return contact;
    const double d = std::sqrt(d2);
    contact.depth = r - d;
    nx = ex / d;
    ny = ey / d;
  } else {  // centre inside: out through the nearest face
    const double gx = b.hx - std::abs(lx), gy = b.hy - std::abs(ly);
    if (gx <= gy) {
      contact.depth = r + gx;
      nx = lx >= 0 ? 1 : -1;
      ny = 0;
    } else {
      contact.depth = r + gy;
      nx = 0;
      ny = ly >= 0 ? 1 : -1;
    }
  }
  contact.n_x = b.c * nx - b.s * ny;
  contact.n_y = b.s * nx + b.c * ny;
  return contact;
}

// Overlap of the projections of a and b on the unit axis (ax, ay), and its
// sign (+1: a lies on the + side of b along the axis).
inline double AxisOverlap(const PlaneShape& a, const PlaneShape& b, double ax, double ay,
                          double* sign) {
  const auto extent = [&](const PlaneShape& r) {
    return r.hx * std::abs(r.c * ax + r.s * ay) + r.hy * std::abs(-r.s * ax + r.c * ay);
  };
  const double d = (a.x - b.x) * ax + (a.y - b.y) * ay;
  *sign = d >= 0 ? 1 : -1;
  return extent(a) + extent(b) - std::abs(d);
}

// Rectangle against rectangle: separating axes (the four face normals), the
// axis of least overlap.
inline PlaneContact BoxBox(const PlaneShape& a, const PlaneShape& b) {
  const double axes[4][2] = {{a.c, a.s}, {-a.s, a.c}, {b.c, b.s}, {-b.s, b.c}};
  PlaneContact contact;
  double best = INFINITY;
  for (const auto& axis : axes) {
    double sign;
    const double overlap = AxisOverlap(a, b, axis[0], axis[1], &sign);
    if (overlap <= 0) return {};
    if (overlap < best) {
      best = overlap;
      contact = {overlap, sign * axis[0], sign * axis[1]};
    }
  }
  return contact;
}

}  // namespace detail

// Contact of A against B (A moves by depth * n to separate).
inline PlaneContact CalcContact(const PlaneShape& a, const PlaneShape& b) {
  if (!a.box && !b.box) {
    const double dx = a.x - b.x, dy = a.y - b.y, r = a.hx + b.hx;
    const double d2 = dx * dx + dy * dy;
    if (d2 >= r * r) return {};
    if (d2 == 0) return {r, 1, 0};  // coincident centres: any direction; +x
    const double d = std::sqrt(d2);
    return {r - d, dx / d, dy / d};
  }
  if (!a.box) return detail::CircleBox(a.x, a.y, a.hx, b);
  if (!b.box) {
    PlaneContact contact = detail::CircleBox(b.x, b.y, b.hx, a);
    contact.n_x = -contact.n_x;
    contact.n_y = -contact.n_y;
    return contact;
  }
  return detail::BoxBox(a, b);
}

}  // namespace swarmsim::planar
