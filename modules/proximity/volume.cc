#include "modules/proximity/volume.h"

#include <algorithm>
#include <cmath>

#include "framework/mesh.h"
#include "framework/random.h"

namespace swarmsim::proximity {
namespace {

// A convex set of Dykstra's sweep, in the sensor frame.
enum class SetKind : uint8_t { kHalfSpace, kCone, kInfiniteCylinder, kSlabZ, kShape, kTriangle };

struct ConvexSet {
  SetKind kind;
  Vec3 n;                              // half-space: n . p <= c (n unit)
  double c = 0;                        // half-space offset; cylinder radius; slab half thickness
  double cos_a = 1, sin_a = 0;         // cone about +z
  const PlacedShape* shape = nullptr;  // kShape
  Pose X_ShS;                          // kShape: the sensor frame in the shape's
  Pose X_SSh;                          // kShape: the shape in the sensor's
  Vec3 a, b, d;                        // kTriangle: its corners, sensor frame
};

// Closest point of the segment [-h, h] z to p, then of the ball of radius r.
Vec3 ProjectCapsule(const Vec3& p, double r, double h) {
  const Vec3 axis{0, 0, std::clamp(p.z, -h, h)};
  const Vec3 v = p - axis;
  const double n2 = v.SquaredNorm();
  if (n2 <= r * r) return p;
  return axis + v * (r / std::sqrt(n2));
}

// Closest point of the solid primitive (its own frame) to p.
Vec3 ProjectPrimitive(const PlacedShape& shape, const Vec3& p) {
  const Vec3& h = shape.half_size;
  switch (shape.kind) {
    case ShapeKind::kBox:
    case ShapeKind::kMesh:  // meshes go triangle by triangle; not reached
      return {std::clamp(p.x, -h.x, h.x), std::clamp(p.y, -h.y, h.y), std::clamp(p.z, -h.z, h.z)};
    case ShapeKind::kSphere: {
      const double n2 = p.SquaredNorm();
      return n2 <= h.x * h.x ? p : p * (h.x / std::sqrt(n2));
    }
    case ShapeKind::kCylinder: {
      // A product set (disc x interval): project each factor.
      const double r2 = p.x * p.x + p.y * p.y;
      const double s = r2 <= h.x * h.x ? 1 : h.x / std::sqrt(r2);
      return {p.x * s, p.y * s, std::clamp(p.z, -h.z, h.z)};
    }
    case ShapeKind::kCapsule: return ProjectCapsule(p, h.x, std::max(0.0, h.z - h.x));
  }
  return p;
}

Vec3 Project(const ConvexSet& set, const Vec3& p) {
  switch (set.kind) {
    case SetKind::kHalfSpace: {
      const double excess = set.n.Dot(p) - set.c;
      return excess <= 0 ? p : p - set.n * excess;
    }
    case SetKind::kCone: {
      // In the (radial, axial) half-plane: inside, in the polar cone (to the
      // apex) or onto the boundary ray (sin a, cos a).
      const double r = std::sqrt(p.x * p.x + p.y * p.y);
      if (r * set.cos_a <= p.z * set.sin_a) return p;
      const double s = r * set.sin_a + p.z * set.cos_a;
      if (s <= 0) return {};
      const double radial = s * set.sin_a;
      const double k = r > 0 ? radial / r : 0;
      return {p.x * k, p.y * k, s * set.cos_a};
    }
    case SetKind::kInfiniteCylinder: {
      const double r2 = p.x * p.x + p.y * p.y;
      if (r2 <= set.c * set.c) return p;
      const double k = set.c / std::sqrt(r2);
      return {p.x * k, p.y * k, p.z};
    }
    case SetKind::kSlabZ: return {p.x, p.y, std::clamp(p.z, -set.c, set.c)};
    case SetKind::kShape: return set.X_SSh * ProjectPrimitive(*set.shape, set.X_ShS * p);
    case SetKind::kTriangle: return ClosestOnTriangle(p, set.a, set.b, set.d);
  }
  return p;
}

// The volume as convex sets (at most 6). Returns their count.
int VolumeSets(const Volume& v, ConvexSet* sets) {
  int n = 0;
  auto half_space = [&](const Vec3& normal, double c) {
    sets[n] = {};
    sets[n].kind = SetKind::kHalfSpace;
    sets[n].n = normal;
    sets[n].c = c;
    ++n;
  };
  switch (v.kind) {
    case ProximityVolume::kCone:
    case ProximityVolume::kRandomizedRay:
      sets[n] = {};
      sets[n].kind = SetKind::kCone;
      sets[n].cos_a = v.cos_angle, sets[n].sin_a = v.sin_angle;
      ++n;
      if (v.blind_zone > 0) half_space({0, 0, -1}, -v.blind_zone);
      break;
    case ProximityVolume::kPyramid:
      half_space({v.cos_x, 0, -v.sin_x}, 0);
      half_space({-v.cos_x, 0, -v.sin_x}, 0);
      half_space({0, v.cos_y, -v.sin_y}, 0);
      half_space({0, -v.cos_y, -v.sin_y}, 0);
      if (v.blind_zone > 0) half_space({0, 0, -1}, -v.blind_zone);
      break;
    case ProximityVolume::kCylinder:
      sets[n] = {};
      sets[n].kind = SetKind::kInfiniteCylinder;
      sets[n].c = v.radius;
      ++n;
      half_space({0, 0, -1}, -v.blind_zone);
      break;
    case ProximityVolume::kDisc:
      sets[n] = {};
      sets[n].kind = SetKind::kSlabZ;
      sets[n].c = v.half_thickness;
      ++n;
      half_space({-v.sin_angle, v.cos_angle, 0}, 0);
      half_space({-v.sin_angle, -v.cos_angle, 0}, 0);
      if (v.blind_zone > 0) half_space({-1, 0, 0}, -v.blind_zone);
      break;
    case ProximityVolume::kRay: break;
  }
  return n;
}

// Dykstra's projection of the origin onto the intersection of `sets`
// (count <= 7). Returns whether the sets meet (within the tolerance); *p the
// point. `scale`: a length of the scene, for the tolerances.
bool ProjectOriginOntoIntersection(const ConvexSet* sets, int count, double scale, Vec3* p) {
  constexpr int kMaxSweeps = 20000;
  Vec3 increments[8] = {};
  Vec3 previous[8] = {};  // each set's projection in the last sweep
  Vec3 x{};
  const double step_tolerance2 = (1e-12 * scale) * (1e-12 * scale);
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    // Converged when neither a projection nor an increment moved (the
    // projections alone may stand still for sweeps while the increments grow).
    double moved2 = 0;
    for (int i = 0; i < count; ++i) {
      const Vec3 y = Project(sets[i], x + increments[i]);
      const Vec3 increment = x + increments[i] - y;
      moved2 += (y - previous[i]).SquaredNorm() + (increment - increments[i]).SquaredNorm();
      increments[i] = increment;
      previous[i] = y;
      x = y;
    }
    if (sweep > 0 && moved2 <= step_tolerance2) break;
  }
  *p = x;
  const double tolerance = 1e-9 * scale;
  for (int i = 0; i < count; ++i)
    if ((Project(sets[i], x) - x).SquaredNorm() > tolerance * tolerance) return false;
  return true;
}

// Is p within `tolerance` of every set?
bool InAll(const ConvexSet* sets, int count, const Vec3& p, double tolerance) {
  for (int i = 0; i < count; ++i)
    if ((Project(sets[i], p) - p).SquaredNorm() > tolerance * tolerance) return false;
  return true;
}

// The root lambda >= 0 of a nonincreasing h (h(lambda, &y) also gives the
// point y(lambda)) by Illinois regula falsi, to 1e-13 of `scale`: *x = y
// there, on the feasible side (h <= 0). False: h stays > 0 (no root).
template <class H>
bool DualRoot(H&& h, double scale, Vec3* x) {
  Vec3 y;
  double lo = 0, h_lo = h(0, &y);
  if (h_lo <= 0) return *x = y, true;
  double hi = scale, h_hi = h(hi, &y);
  for (int k = 0; h_hi > 0; ++k) {
    if (k == 60) return false;
    lo = hi, h_lo = h_hi;
    hi *= 4;
    h_hi = h(hi, &y);
  }
  *x = y;  // feasible
  int side = 0;
  for (int i = 0; i < 200 && hi - lo > 1e-13 * scale; ++i) {
    double m = hi - h_hi * (hi - lo) / (h_hi - h_lo);
    if (!(m > lo && m < hi)) m = 0.5 * (lo + hi);
    const double hm = h(m, &y);
    if (hm > 0) {
      lo = m, h_lo = hm;
      if (side == 1) h_hi *= 0.5;
      side = 1;
    } else {
      *x = y;
      if (hm == 0) break;
      hi = m, h_hi = hm;
      if (side == -1) h_lo *= 0.5;
      side = -1;
    }
  }
  return true;
}

// The point of S ∩ {n . x <= c} (n unit) nearest q: x = P_S(q - lambda n)
// at the root of n . x(lambda) = c (the Lagrange dual of the one
// constraint; n . x(lambda) is nonincreasing). False: S misses it.
bool NearestInHalfSpace(const ConvexSet& shape, const Vec3& q, const Vec3& n, double c,
                        double scale, Vec3* x) {
  return DualRoot(
      [&](double lambda, Vec3* y) {
        *y = Project(shape, q - n * lambda);
        return n.Dot(*y) - c;
      },
      scale, x);
}

// min |x| over S ∩ H1 ∩ H2: the root lambda2 of n2 . x(lambda2) = c2,
// x(lambda2) the point of S ∩ H1 nearest -lambda2 n2 (nonincreasing: the
// derivative of a concave dual). False: they do not meet.
bool NearestInTwoHalfSpaces(const ConvexSet& shape, const Vec3& n1, double c1, const Vec3& n2,
                            double c2, double scale, Vec3* x) {
  if (!NearestInHalfSpace(shape, {}, n1, c1, scale, x)) return false;
  return DualRoot(
      [&](double lambda, Vec3* y) {
        NearestInHalfSpace(shape, n2 * -lambda, n1, c1, scale, y);
        return n2.Dot(*y) - c2;
      },
      scale, x);
}

// min |x| over S ∩ (a cone or cylinder piece) through its supporting
// half-spaces: at the answer's azimuth phi, the half-space tangent there
// gives the same answer, so iterate phi <- azimuth of that half-space's
// answer. *found: an answer in every set of the volume.
bool NearestThroughTangents(const ConvexSet* sets, int count, const ConvexSet& piece,
                            const Vec3& start, double scale, Vec3* x, bool* found) {
  double phi = std::atan2(start.y, start.x);
  for (int k = 0; k < 40; ++k) {
    const double cp = std::cos(phi), sp = std::sin(phi);
    const bool cone = piece.kind == SetKind::kCone;
    const Vec3 n = cone ? Vec3{piece.cos_a * cp, piece.cos_a * sp, -piece.sin_a} : Vec3{cp, sp, 0};
    if (!NearestInHalfSpace(sets[0], {}, n, cone ? 0 : piece.c, scale, x)) return false;
    if (InAll(sets + 1, count - 1, *x, 1e-9 * scale)) return *found = true;
    const double next = std::atan2(x->y, x->x);
    if (std::abs(std::remainder(next - phi, 2 * M_PI)) < 1e-14) break;
    phi = next;
  }
  return true;
}

// min |x| over sets[0] (the shape) ∩ sets[1..count) (the volume), when the
// shape's own nearest point `start` is outside the volume. First the
// relaxations to one piece of the volume (exact, a few dozen projections),
// then to two half-spaces where one's answer violates the other (a
// pyramid's edge): an answer that lies in the whole volume is the answer.
// Else Dykstra. False: they do not meet.
bool NearestInIntersection(const ConvexSet* sets, int count, const Vec3& start, double scale,
                           Vec3* x) {
  const double tolerance = 1e-9 * scale;
  // The half-spaces (a slab: its face on start's side), their answers.
  Vec3 normals[8], answers[8];
  double offsets[8];
  int planes = 0;
  for (int i = 1; i < count; ++i) {
    const ConvexSet& piece = sets[i];
    if ((Project(piece, start) - start).SquaredNorm() == 0) continue;  // not what cuts it
    bool found = false;
    switch (piece.kind) {
      case SetKind::kHalfSpace:
      case SetKind::kSlabZ:
        normals[planes] =
            piece.kind == SetKind::kHalfSpace ? piece.n : Vec3{0, 0, start.z > 0 ? 1.0 : -1.0};
        offsets[planes] = piece.c;
        if (!NearestInHalfSpace(sets[0], {}, normals[planes], offsets[planes], scale, x))
          return false;
        found = InAll(sets + 1, count - 1, *x, tolerance);
        answers[planes++] = *x;
        break;
      case SetKind::kCone:
      case SetKind::kInfiniteCylinder:
        if (!NearestThroughTangents(sets, count, piece, start, scale, x, &found)) return false;
        break;
      default: break;
    }
    if (found) return true;
  }
  for (int a = 0; a < planes; ++a)
    for (int b = 0; b < planes; ++b) {
      if (a == b || normals[b].Dot(answers[a]) - offsets[b] <= tolerance) continue;
      if (!NearestInTwoHalfSpaces(sets[0], normals[a], offsets[a], normals[b], offsets[b], scale,
                                  x))
        return false;
      if (InAll(sets + 1, count - 1, *x, tolerance)) return true;
    }
  return ProjectOriginOntoIntersection(sets, count, scale, x);
}

// Outward normal of a primitive (own frame) at its surface point nearest p.
// On an edge or a corner, of the faces that meet there, the one facing
// `toward` most (the direction back to the sensor; zero: the first).
Vec3 PrimitiveNormal(const PlacedShape& shape, const Vec3& p, const Vec3& toward = {}) {
  const Vec3& h = shape.half_size;
  const double tolerance = 1e-9 * std::max({h.x, h.y, h.z, 1e-300});
  switch (shape.kind) {
    case ShapeKind::kBox:
    case ShapeKind::kMesh: {
      // The faces with the least slack (outside: the most excess).
      const double slack[3] = {h.x - std::abs(p.x), h.y - std::abs(p.y), h.z - std::abs(p.z)};
      const Vec3 faces[3] = {{std::copysign(1.0, p.x), 0, 0},
                             {0, std::copysign(1.0, p.y), 0},
                             {0, 0, std::copysign(1.0, p.z)}};
      const double least = std::min({slack[0], slack[1], slack[2]});
      int best = -1;
      for (int i = 0; i < 3; ++i)
        if (slack[i] <= least + tolerance &&
            (best < 0 || faces[i].Dot(toward) > faces[best].Dot(toward)))
          best = i;
      return faces[best];
    }
    case ShapeKind::kSphere: return p.SquaredNorm() > 0 ? p.Normalized() : Vec3{0, 0, 1};
    case ShapeKind::kCylinder: {
      const double r = std::sqrt(p.x * p.x + p.y * p.y);
      const double side_slack = h.x - r, cap_slack = h.z - std::abs(p.z);
      const Vec3 cap{0, 0, std::copysign(1.0, p.z)};
      if (r > 0 && std::abs(side_slack - cap_slack) <= tolerance) {  // on the rim
        const Vec3 side{p.x / r, p.y / r, 0};
        return side.Dot(toward) > cap.Dot(toward) ? side : cap;
      }
      if (side_slack < cap_slack && r > 0) return {p.x / r, p.y / r, 0};
      return cap;
    }
    case ShapeKind::kCapsule: {
      const Vec3 v = p - Vec3{0, 0, std::clamp(p.z, -(h.z - h.x), h.z - h.x)};
      return v.SquaredNorm() > 0 ? v.Normalized() : Vec3{1, 0, 0};
    }
  }
  return {0, 0, 1};
}

// Does the detected point pass the reflectance cut-off?
bool PassesCutOff(const Volume& v, const Vec3& point, const Vec3& normal) {
  if (v.cos_max_detection_angle <= -1) return true;
  const double d = point.Norm();
  if (!(d > 0)) return true;
  return -point.Dot(normal) >= v.cos_max_detection_angle * d;
}

double SceneScale(const Volume& v, const Vec3& centre, double size) {
  return 1 + v.range + centre.Norm() + size;
}

// Squared distance from p to the box [lo, hi] (0 inside).
double BoxDistance2(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  auto gap = [](double v, double a, double b) { return v < a ? a - v : v > b ? v - b : 0.0; };
  return Vec3{gap(p.x, lo.x, hi.x), gap(p.y, lo.y, hi.y), gap(p.z, lo.z, hi.z)}.SquaredNorm();
}

// Calls visit(triangle) for the mesh's triangles in BVH leaves within
// *reach2 (squared, may shrink as visit runs) of p (mesh frame).
template <class Visit>
void VisitTrianglesNear(const TriangleMesh& mesh, const Vec3& p, const double* reach2,
                        Visit&& visit) {
  const auto nodes = mesh.bvh();
  if (nodes.empty()) return;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const MeshBvhNode& node = nodes[stack[--top]];
    if (BoxDistance2(p, node.lo, node.hi) > *reach2) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) visit(mesh.triangles()[i]);
    } else if (top + 2 <= 64) {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
    }
  }
}

bool NearestOnMesh(const Volume& v, const ConvexSet* volume_sets, int count,
                   const PlacedShape& shape, const Pose& X_SSh, double best, VolumeHit* hit) {
  const TriangleMesh& mesh = *shape.mesh;
  const auto vertices = mesh.vertices();
  const double scale = SceneScale(v, X_SSh.p, 2 * shape.half_size.Norm());
  const double tolerance = 1e-9 * scale;
  bool found = false;
  ConvexSet sets[8];
  std::copy(volume_sets, volume_sets + count, sets + 1);
  // Triangles whose BVH box is nearer than the best (and than the range).
  const Vec3 origin_Sh = X_SSh.Inverse().p;
  double reach2 = std::min(best, v.range) * std::min(best, v.range);
  if (!std::isfinite(reach2)) reach2 = INFINITY;
  VisitTrianglesNear(mesh, origin_Sh, &reach2, [&](const MeshTriangle& t) {
    const Vec3 a = X_SSh * vertices[t.v[0]], b = X_SSh * vertices[t.v[1]],
               c = X_SSh * vertices[t.v[2]];
    const Vec3 cross = (b - a).Cross(c - a);
    if (!(cross.SquaredNorm() > 0)) return;
    const Vec3 normal = cross.Normalized();
    // Front: the sensor is on the triangle's outer side.
    const bool front = normal.Dot(a) < 0;
    if (front ? !v.detect_front : !v.detect_back) return;
    Vec3 p = ClosestOnTriangle({}, a, b, c);
    double d = p.Norm();
    if (d >= best || d > v.range) return;  // no nearer point on it
    if (!InVolume(v, p, tolerance)) {
      sets[0] = {};
      sets[0].kind = SetKind::kTriangle;
      sets[0].a = a, sets[0].b = b, sets[0].d = c;
      if (!NearestInIntersection(sets, count + 1, p, scale, &p)) return;
      d = p.Norm();
      if (d >= best || d > v.range) return;
    }
    if (!PassesCutOff(v, p, normal)) return;
    best = d;
    reach2 = d * d;
    *hit = {d, p, normal};
    found = true;
  });
  return found;
}

}  // namespace

Volume MakeVolume(const ProximitySensorData& s) {
  Volume v;
  v.kind = s.volume();
  v.range = s.range();
  v.cos_angle = std::cos(s.settings->angle), v.sin_angle = std::sin(s.settings->angle);
  v.cos_x = std::cos(s.settings->angle), v.sin_x = std::sin(s.settings->angle);
  v.cos_y = std::cos(s.settings->angle_y), v.sin_y = std::sin(s.settings->angle_y);
  v.radius = s.settings->radius;
  v.half_thickness = 0.5 * s.settings->thickness;
  v.blind_zone = s.settings->blind_zone;
  v.cos_max_detection_angle = s.settings->max_detection_angle >= 3.141592653589793
                                  ? -1
                                  : std::cos(s.settings->max_detection_angle);
  v.detect_front = s.settings->detect_front, v.detect_back = s.settings->detect_back;
  return v;
}

void VolumeBounds(const Volume& v, Vec3* lo, Vec3* hi) {
  const double r = v.range;
  switch (v.kind) {
    case ProximityVolume::kCylinder:
      *lo = {-v.radius, -v.radius, v.blind_zone};
      *hi = {v.radius, v.radius, r};
      return;
    case ProximityVolume::kDisc:
      *lo = {v.cos_angle < 0 ? -r : 0, -r, -v.half_thickness};
      *hi = {r, r, v.half_thickness};
      return;
    case ProximityVolume::kPyramid:
      *lo = {-r * v.sin_x, -r * v.sin_y, 0};
      *hi = {r * v.sin_x, r * v.sin_y, r};
      return;
    default:  // cones
      *lo = {-r * v.sin_angle, -r * v.sin_angle, 0};
      *hi = {r * v.sin_angle, r * v.sin_angle, r};
      return;
  }
}

bool InVolume(const Volume& v, const Vec3& p, double tolerance) {
  ConvexSet sets[8];
  const int n = VolumeSets(v, sets);
  for (int i = 0; i < n; ++i)
    if ((Project(sets[i], p) - p).SquaredNorm() > tolerance * tolerance) return false;
  return true;
}

bool NearestInVolume(const Volume& v, const PlacedShape& shape, const Pose& X_SW, double best,
                     VolumeHit* hit) {
  ConvexSet sets[8];
  const int count = VolumeSets(v, sets + 1);
  const Pose X_SSh = X_SW * shape.X_WS;
  if (shape.kind == ShapeKind::kMesh)
    return shape.mesh && NearestOnMesh(v, sets + 1, count, shape, X_SSh, best, hit);
  sets[0] = {};
  sets[0].kind = SetKind::kShape;
  sets[0].shape = &shape;
  sets[0].X_SSh = X_SSh;
  sets[0].X_ShS = X_SSh.Inverse();
  const double scale = SceneScale(v, X_SSh.p, 2 * shape.half_size.Norm());
  // Its bounding sphere misses a piece of the volume: nothing to find.
  const double bounding_radius =
      shape.kind == ShapeKind::kSphere ? shape.half_size.x : shape.half_size.Norm();
  for (int i = 1; i <= count; ++i)
    if ((Project(sets[i], X_SSh.p) - X_SSh.p).Norm() > bounding_radius + 1e-9 * scale) return false;
  // The shape's own nearest point: a lower bound, and the answer if inside.
  Vec3 p = Project(sets[0], {});
  double d = p.Norm();
  if (d >= best || d > v.range) return false;
  if (!InVolume(v, p, 1e-9 * scale)) {
    if (!NearestInIntersection(sets, count + 1, p, scale, &p)) return false;
    d = p.Norm();
    if (d >= best || d > v.range) return false;
  }
  const Vec3 normal =
      X_SSh.q.Rotate(PrimitiveNormal(shape, sets[0].X_ShS * p, sets[0].X_ShS.q.Rotate(Vec3{} - p)));
  if (!PassesCutOff(v, p, normal)) return false;
  *hit = {d, p, normal};
  return true;
}

Vec3 SurfaceNormal(const PlacedShape& shape, const Vec3& p_W) {
  const Vec3 p = shape.X_SW * p_W;
  if (shape.kind != ShapeKind::kMesh) return shape.X_WS.q.Rotate(PrimitiveNormal(shape, p));
  if (!shape.mesh) return {0, 0, 1};
  // The nearest triangle's normal.
  const auto vertices = shape.mesh->vertices();
  double best = INFINITY;
  Vec3 normal{0, 0, 1};
  VisitTrianglesNear(*shape.mesh, p, &best, [&](const MeshTriangle& t) {
    const Vec3 &a = vertices[t.v[0]], &b = vertices[t.v[1]], &c = vertices[t.v[2]];
    const double d = (ClosestOnTriangle(p, a, b, c) - p).SquaredNorm();
    const Vec3 cross = (b - a).Cross(c - a);
    if (d < best && cross.SquaredNorm() > 0) best = d, normal = cross.Normalized();
  });
  return shape.X_WS.q.Rotate(normal);
}

void RandomRayDirections(uint64_t seed, uint64_t stream, double angle, uint32_t count, Vec3* out) {
  Rng rng(seed, stream);
  const double one_minus_cos = 1 - std::cos(angle);
  for (uint32_t i = 0; i < count; ++i) {
    const double cos_t = 1 - rng.Uniform() * one_minus_cos;
    const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
    const double phi = 2 * 3.141592653589793 * rng.Uniform();
    out[i] = {sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t};
  }
}

}  // namespace swarmsim::proximity
