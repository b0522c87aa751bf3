#include "modules/proximity/ray_cast.h"

#include <algorithm>
#include <cmath>

namespace swarmsim::proximity {
namespace {

double Component(const Vec3& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }

// Intersects [*t_lo, *t_hi] with the t where lo <= o + t d <= hi along one
// axis. False if the interval becomes empty.
bool ClipSlab(double o, double d, double lo, double hi, double* t_lo, double* t_hi) {
  if (d == 0) return o >= lo && o <= hi;
  const double inv = 1 / d;
  double t1 = (lo - o) * inv, t2 = (hi - o) * inv;
  if (t1 > t2) std::swap(t1, t2);
  *t_lo = std::max(*t_lo, t1);
  *t_hi = std::min(*t_hi, t2);
  return *t_lo <= *t_hi;
}

// Intersects [*t_lo, *t_hi] with the t where |o + t d|^2 <= r^2, the norm
// taken over the first `dims` components (2: infinite z cylinder, 3: sphere).
bool ClipQuadric(const Vec3& o, const Vec3& d, double r, int dims, double* t_lo, double* t_hi) {
  const Vec3 o2 = dims == 3 ? o : Vec3{o.x, o.y, 0};
  const Vec3 d2 = dims == 3 ? d : Vec3{d.x, d.y, 0};
  const double a = d2.SquaredNorm();
  const double c = o2.SquaredNorm() - r * r;
  if (a == 0) return c <= 0;  // parallel to the axis: inside for all t or none
  const double b = o2.Dot(d2);
  // b^2 - a c, written without the cancellation of b^2 against a |o|^2.
  const double disc = a * r * r - o2.Cross(d2).SquaredNorm();
  if (disc < 0) return false;
  const double q = -(b + std::copysign(std::sqrt(disc), b));
  double t1 = q / a, t2 = q != 0 ? c / q : t1;
  if (t1 > t2) std::swap(t1, t2);
  *t_lo = std::max(*t_lo, t1);
  *t_hi = std::min(*t_hi, t2);
  return *t_lo <= *t_hi;
}

}  // namespace

bool RayBox(const Vec3& o, const Vec3& d, const Vec3& h, double max_t, double* t) {
  double lo = 0, hi = max_t;
  if (!ClipSlab(o.x, d.x, -h.x, h.x, &lo, &hi) || !ClipSlab(o.y, d.y, -h.y, h.y, &lo, &hi) ||
      !ClipSlab(o.z, d.z, -h.z, h.z, &lo, &hi))
    return false;
  *t = lo;
  return true;
}

bool RayCylinder(const Vec3& o, const Vec3& d, double radius, double half_height, double max_t,
                 double* t) {
  double lo = 0, hi = max_t;
  if (!ClipSlab(o.z, d.z, -half_height, half_height, &lo, &hi) ||
      !ClipQuadric(o, d, radius, 2, &lo, &hi))
    return false;
  *t = lo;
  return true;
}

bool RaySphere(const Vec3& o, const Vec3& d, double radius, double max_t, double* t) {
  double lo = 0, hi = max_t;
  if (!ClipQuadric(o, d, radius, 3, &lo, &hi)) return false;
  *t = lo;
  return true;
}

PlacedShape PlaceShape(const ShapeData& shape, const Pose& X_WS, ObjectId id, int instance) {
  PlacedShape placed;
  placed.X_WS = X_WS;
  placed.X_SW = X_WS.Inverse();
  placed.id = id;
  placed.instance = instance;
  placed.kind = shape.kind;
  switch (shape.kind) {
    case ShapeKind::kBox: placed.half_size = shape.size * 0.5; break;
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:  // approximated by its bounding cylinder
      placed.half_size = {shape.size.x, shape.size.x, shape.size.z * 0.5};
      break;
    case ShapeKind::kSphere: placed.half_size = {shape.size.x, shape.size.x, shape.size.x}; break;
    case ShapeKind::kMesh:
      placed.mesh = shape.mesh.get();
      placed.half_size = placed.mesh ? (placed.mesh->hi() - placed.mesh->lo()) * 0.5 : Vec3{};
      break;
  }
  return placed;
}

bool RayCast(const PlacedShape& shape, const Vec3& p_W, const Vec3& d_W, double max_t, double* t) {
  const Vec3 o = shape.X_SW * p_W;
  const Vec3 d = shape.X_SW.q.Rotate(d_W);
  switch (shape.kind) {
    case ShapeKind::kBox: return RayBox(o, d, shape.half_size, max_t, t);
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
      return RayCylinder(o, d, shape.half_size.x, shape.half_size.z, max_t, t);
    case ShapeKind::kSphere: return RaySphere(o, d, shape.half_size.x, max_t, t);
    case ShapeKind::kMesh: return shape.mesh && shape.mesh->RayCast(o, d, max_t, t);
  }
  return false;
}

void WorldBounds(const PlacedShape& shape, Vec3* lo, Vec3* hi) {
  const Quat& q = shape.X_WS.q;
  const Vec3& h = shape.half_size;
  Vec3 extent;
  Vec3 p_WC = shape.X_WS.p;  // centre of the bounds
  if (shape.kind == ShapeKind::kMesh && shape.mesh)
    p_WC = shape.X_WS * ((shape.mesh->lo() + shape.mesh->hi()) * 0.5);
  if (shape.kind == ShapeKind::kSphere) {
    extent = h;
  } else if (shape.kind == ShapeKind::kCylinder || shape.kind == ShapeKind::kCapsule) {
    // A disc of radius r perpendicular to the axis a reaches r sqrt(1 - a_i^2) along axis i.
    const Vec3 a = q.Rotate({0, 0, 1});
    auto reach = [&](double ai) {
      return h.x * std::sqrt(std::max(0.0, 1 - ai * ai)) + h.z * std::abs(ai);
    };
    extent = {reach(a.x), reach(a.y), reach(a.z)};
  } else {
    const Vec3 ax = q.Rotate({1, 0, 0}), ay = q.Rotate({0, 1, 0}), az = q.Rotate({0, 0, 1});
    extent = {std::abs(ax.x) * h.x + std::abs(ay.x) * h.y + std::abs(az.x) * h.z,
              std::abs(ax.y) * h.x + std::abs(ay.y) * h.y + std::abs(az.y) * h.z,
              std::abs(ax.z) * h.x + std::abs(ay.z) * h.y + std::abs(az.z) * h.z};
  }
  *lo = p_WC - extent;
  *hi = p_WC + extent;
}

double WorldFootprintRadius(const ShapeData& shape, const Pose& X_WS) {
  return WorldFootprintRadius(shape, X_WS, nullptr);
}

double WorldFootprintRadius(const ShapeData& shape, const Pose& X_WS, FootprintMemo* memo) {
  const Vec3 axis = X_WS.q.Rotate({0, 0, 1});
  if (std::abs(axis.z) >= 1 - 1e-12) return shape.BoundingRadius();  // upright
  switch (shape.kind) {
    case ShapeKind::kBox: return 0.5 * shape.size.Norm();
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
      if (memo == nullptr) return std::hypot(shape.size.x, 0.5 * shape.size.z);
      if (!(memo->size_x == shape.size.x && memo->size_z == shape.size.z))
        *memo = {shape.size.x, shape.size.z, std::hypot(shape.size.x, 0.5 * shape.size.z)};
      return memo->radius;
    case ShapeKind::kSphere: return shape.size.x;
    case ShapeKind::kMesh: return shape.mesh ? shape.mesh->bounding_radius() : 0;
  }
  return 0;
}

namespace {

// Separating-axis test between the cube (centre c, half edge a) and the
// oriented box (pose X_WB, half extents b), each grown by `margin`
// (Ericson, Real-Time Collision Detection, 4.4.1, with A = world axes).
bool CubeMeetsBox(const Vec3& c, double a_half, const Pose& X_WB, const Vec3& b_half,
                  double margin) {
  const Vec3 col[3] = {X_WB.q.Rotate({1, 0, 0}), X_WB.q.Rotate({0, 1, 0}),
                       X_WB.q.Rotate({0, 0, 1})};
  double R[3][3], abs_R[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      R[i][j] = Component(col[j], i);
      abs_R[i][j] = std::abs(R[i][j]) + 1e-12;  // robust when an edge pair is parallel
    }
  const Vec3 tv = X_WB.p - c;
  const double t[3] = {tv.x, tv.y, tv.z};
  const double a[3] = {a_half, a_half, a_half};
  const double b[3] = {b_half.x, b_half.y, b_half.z};
  // World axes.
  for (int i = 0; i < 3; ++i) {
    const double rb = b[0] * abs_R[i][0] + b[1] * abs_R[i][1] + b[2] * abs_R[i][2];
    if (std::abs(t[i]) > a[i] + rb + margin) return false;
  }
  // Box axes.
  for (int j = 0; j < 3; ++j) {
    const double ra = a[0] * abs_R[0][j] + a[1] * abs_R[1][j] + a[2] * abs_R[2][j];
    const double dist = std::abs(t[0] * R[0][j] + t[1] * R[1][j] + t[2] * R[2][j]);
    if (dist > ra + b[j] + margin) return false;
  }
  // Cross products of world axis i and box axis j.
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = a[i1] * abs_R[i2][j] + a[i2] * abs_R[i1][j];
      const double rb = b[j1] * abs_R[i][j2] + b[j2] * abs_R[i][j1];
      const double dist = std::abs(t[i2] * R[i1][j] - t[i1] * R[i2][j]);
      if (dist > ra + rb + margin) return false;
    }
  }
  return true;
}

}  // namespace

bool MayOverlapCube(const PlacedShape& shape, const Vec3& centre, double half, double margin) {
  switch (shape.kind) {
    case ShapeKind::kBox: return CubeMeetsBox(centre, half, shape.X_WS, shape.half_size, margin);
    case ShapeKind::kSphere: {
      const Vec3 d = shape.X_WS.p - centre;
      auto outside = [half](double v) { return std::max(std::abs(v) - half, 0.0); };
      const Vec3 gap{outside(d.x), outside(d.y), outside(d.z)};
      const double reach = shape.half_size.x + margin;
      return gap.SquaredNorm() <= reach * reach;
    }
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule: {
      if (!CubeMeetsBox(centre, half, shape.X_WS, shape.half_size, margin)) return false;
      // The cube's centre must lie within r + its half diagonal of the axis segment.
      const Vec3 c = shape.X_SW * centre;
      const double dz = std::max(std::abs(c.z) - shape.half_size.z, 0.0);
      const double reach = shape.half_size.x + std::sqrt(3.0) * half + margin;
      return c.x * c.x + c.y * c.y + dz * dz <= reach * reach;
    }
    case ShapeKind::kMesh: {
      if (!shape.mesh) return false;
      // The cube must meet the mesh's bounds, and its bounding sphere a triangle.
      const Pose X_WC{shape.X_WS * ((shape.mesh->lo() + shape.mesh->hi()) * 0.5), shape.X_WS.q};
      if (!CubeMeetsBox(centre, half, X_WC, shape.half_size, margin)) return false;
      return shape.mesh->AnyTriangleWithin(shape.X_SW * centre, std::sqrt(3.0) * half + margin);
    }
  }
  return true;
}

}  // namespace swarmsim::proximity
