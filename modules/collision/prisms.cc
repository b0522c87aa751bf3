#include "modules/collision/prisms.h"

#include <algorithm>
#include <cmath>

namespace swarmsim::collision {

namespace {

constexpr double kUpright = 1e-12;  // |1 - z.z'| below which an axis counts as vertical

struct P2 {
  double x, y;
};

// The z axis of `q` turned by it: vertical? Sets the heading of its x axis.
bool Upright(const Quat& q, double* c, double* s) {
  const Vec3 z = q.Rotate({0, 0, 1});
  if (z.z < 1 - kUpright) return false;
  const Vec3 x = q.Rotate({1, 0, 0});
  const double n = std::sqrt(x.x * x.x + x.y * x.y);
  *c = x.x / n;
  *s = x.y / n;
  return true;
}

// Closest point of rectangle `r` to p, and whether p is inside.
P2 ClosestOnRect(const Prism& r, P2 p, bool* inside) {
  const double dx = p.x - r.cx, dy = p.y - r.cy;
  const double lx = r.c * dx + r.s * dy, ly = -r.s * dx + r.c * dy;
  const double qx = std::clamp(lx, -r.hx, r.hx), qy = std::clamp(ly, -r.hy, r.hy);
  *inside = qx == lx && qy == ly;
  return {r.cx + r.c * qx - r.s * qy, r.cy + r.s * qx + r.c * qy};
}

void Corners(const Prism& r, P2 out[4]) {
  const double sx[4] = {1, -1, -1, 1}, sy[4] = {1, 1, -1, -1};
  for (int i = 0; i < 4; ++i) {
    const double lx = sx[i] * r.hx, ly = sy[i] * r.hy;
    out[i] = {r.cx + r.c * lx - r.s * ly, r.cy + r.s * lx + r.c * ly};
  }
}

// Separated along one of the rectangles' axes (SAT)?
bool Separated(const Prism& a, const Prism& b) {
  P2 ca[4], cb[4];
  Corners(a, ca);
  Corners(b, cb);
  const P2 axes[4] = {{a.c, a.s}, {-a.s, a.c}, {b.c, b.s}, {-b.s, b.c}};
  for (const P2& ax : axes) {
    double a0 = INFINITY, a1 = -INFINITY, b0 = INFINITY, b1 = -INFINITY;
    for (int i = 0; i < 4; ++i) {
      const double pa = ca[i].x * ax.x + ca[i].y * ax.y, pb = cb[i].x * ax.x + cb[i].y * ax.y;
      a0 = std::min(a0, pa), a1 = std::max(a1, pa), b0 = std::min(b0, pb), b1 = std::max(b1, pb);
    }
    if (a1 < b0 || b1 < a0) return true;
  }
  return false;
}

// 2D distance and closest points; false when the footprints overlap.
bool Distance2(const Prism& a, const Prism& b, double* d, P2* pa, P2* pb) {
  if (a.kind == Prism::kCircle && b.kind == Prism::kCircle) {
    const double dx = b.cx - a.cx, dy = b.cy - a.cy, n = std::sqrt(dx * dx + dy * dy);
    *d = n - a.hx - b.hx;
    if (!(*d > 0)) return false;
    *pa = {a.cx + dx / n * a.hx, a.cy + dy / n * a.hx};
    *pb = {b.cx - dx / n * b.hx, b.cy - dy / n * b.hx};
    return true;
  }
  if (a.kind == Prism::kRect && b.kind == Prism::kCircle) {
    if (!Distance2(b, a, d, pb, pa)) return false;
    return true;
  }
  if (a.kind == Prism::kCircle) {  // b a rectangle
    bool inside = false;
    const P2 q = ClosestOnRect(b, {a.cx, a.cy}, &inside);
    if (inside) return false;
    const double dx = q.x - a.cx, dy = q.y - a.cy, n = std::sqrt(dx * dx + dy * dy);
    *d = n - a.hx;
    if (!(*d > 0)) return false;
    *pa = {a.cx + dx / n * a.hx, a.cy + dy / n * a.hx};
    *pb = q;
    return true;
  }
  // Two rectangles: apart, the nearest pair has a corner of one of them.
  if (!Separated(a, b)) return false;
  P2 corners[4];
  *d = INFINITY;
  const auto consider = [&](const Prism& from, const Prism& to, bool swap) {
    Corners(from, corners);
    for (const P2& p : corners) {
      bool inside = false;
      const P2 q = ClosestOnRect(to, p, &inside);
      const double n = std::sqrt((q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y));
      if (n < *d) {
        *d = n;
        *pa = swap ? q : p;
        *pb = swap ? p : q;
      }
    }
  };
  consider(a, b, false);
  consider(b, a, true);
  return *d > 0;
}

}  // namespace

Prism BoxPrism(const Pose& X, const Vec3& size) {
  Prism p;
  if (!Upright(X.q, &p.c, &p.s)) return p;
  p.kind = Prism::kRect;
  p.cx = X.p.x, p.cy = X.p.y;
  p.hx = size.x / 2, p.hy = size.y / 2;
  p.z0 = X.p.z - size.z / 2, p.z1 = X.p.z + size.z / 2;
  return p;
}

Prism CylinderPrism(const Pose& X, double radius, double height) {
  Prism p;
  if (!Upright(X.q, &p.c, &p.s)) return p;
  p.kind = Prism::kCircle;
  p.cx = X.p.x, p.cy = X.p.y;
  p.hx = p.hy = radius;
  p.z0 = X.p.z - height / 2, p.z1 = X.p.z + height / 2;
  return p;
}

Prism LyingCylinderBound(const Pose& X, double radius, double height) {
  Prism p;
  const Vec3 u = X.q.Rotate({0, 0, 1});
  if (std::abs(u.z) > kUpright) return p;
  const double n = std::sqrt(u.x * u.x + u.y * u.y);
  p.kind = Prism::kRect;
  p.exact = false;
  p.c = u.x / n, p.s = u.y / n;
  p.cx = X.p.x, p.cy = X.p.y;
  p.hx = height / 2, p.hy = radius;
  p.z0 = X.p.z - radius, p.z1 = X.p.z + radius;
  return p;
}

bool PrismDistance(const Prism& a, const Prism& b, double* d, Vec3* pa, Vec3* pb) {
  if (a.kind == Prism::kNone || b.kind == Prism::kNone) return false;
  double d2 = 0;
  P2 qa{}, qb{};
  if (!Distance2(a, b, &d2, &qa, &qb)) return false;
  double za, zb;
  const double lo = std::max(a.z0, b.z0), hi = std::min(a.z1, b.z1);
  if (lo <= hi) {
    za = zb = (lo + hi) / 2;
  } else if (a.z1 < b.z0) {
    za = a.z1, zb = b.z0;
  } else {
    za = a.z0, zb = b.z1;
  }
  *d = std::sqrt(d2 * d2 + (zb - za) * (zb - za));
  *pa = {qa.x, qa.y, za};
  *pb = {qb.x, qb.y, zb};
  return true;
}

}  // namespace swarmsim::collision
