#include "framework/mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "framework/error.h"

namespace swarmsim {
namespace {

constexpr uint32_t kLeafTriangles = 4;
// Nodes of this many triangles or more call the constructor's check (a few
// tens of calls for a million triangles, each tens of milliseconds apart).
constexpr uint32_t kCheckTriangles = 1 << 15;
constexpr int kMaxStack = 64;  // median splits: depth <= log2(2^32 / 4) + 1
constexpr double kInf = std::numeric_limits<double>::infinity();

double Axis(const Vec3& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }
Vec3 Min(const Vec3& a, const Vec3& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
Vec3 Max(const Vec3& a, const Vec3& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}

// Entry t of the ray into the box within [0, max_t], or +inf if it misses.
double EnterBox(const Vec3& o, const Vec3& d, const MeshBvhNode& n, double max_t) {
  double lo = 0, hi = max_t;
  for (int i = 0; i < 3; ++i) {
    const double oi = Axis(o, i), di = Axis(d, i), a = Axis(n.lo, i), b = Axis(n.hi, i);
    if (di == 0) {
      if (oi < a || oi > b) return kInf;
      continue;
    }
    double t1 = (a - oi) / di, t2 = (b - oi) / di;
    if (t1 > t2) std::swap(t1, t2);
    lo = std::max(lo, t1);
    hi = std::min(hi, t2);
    if (lo > hi) return kInf;
  }
  return lo;
}

// Moller-Trumbore: t of the hit on triangle (a, b, c), or false. *det > 0
// when the ray comes from the triangle's front (counter-clockwise) side.
bool RayTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c,
                 double* t, double* det_out) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = d.Cross(e2);
  const double det = e1.Dot(p);
  // Parallel to the plane (relative to the triangle's size): no single hit point.
  if (det * det <= 1e-24 * e1.SquaredNorm() * e2.SquaredNorm()) return false;
  const double inv = 1 / det;
  const Vec3 s = o - a;
  const double u = s.Dot(p) * inv;
  if (u < 0 || u > 1) return false;
  const Vec3 q = s.Cross(e1);
  const double v = d.Dot(q) * inv;
  if (v < 0 || u + v > 1) return false;
  *t = e2.Dot(q) * inv;
  *det_out = det;
  return true;
}

}  // namespace

Vec3 ClosestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.Dot(ap), d2 = ac.Dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.Dot(bp), d4 = ac.Dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.Dot(cp), d6 = ac.Dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

TriangleMesh::TriangleMesh(std::string name, std::vector<Vec3> vertices,
                           std::vector<MeshTriangle> triangles, std::vector<Vec3> colors,
                           const std::function<void()>& check)
    : name_(std::move(name)), vertices_(std::move(vertices)) {
  if (!colors.empty() && colors.size() != triangles.size())
    throw Error("mesh '" + name_ + "' has " + std::to_string(colors.size()) + " colours for " +
                std::to_string(triangles.size()) + " triangles");
  std::vector<uint32_t> origin;  // input index of each kept triangle
  const uint32_t n = static_cast<uint32_t>(vertices_.size());
  for (const Vec3& v : vertices_)
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw Error("mesh '" + name_ + "' has a non-finite vertex");
  triangles_.reserve(triangles.size());
  for (const MeshTriangle& tri : triangles) {
    if (tri.v[0] >= n || tri.v[1] >= n || tri.v[2] >= n)
      throw Error("mesh '" + name_ + "' has a triangle with a vertex index out of range");
    if (tri.v[0] == tri.v[1] || tri.v[1] == tri.v[2] || tri.v[0] == tri.v[2]) continue;
    // Degenerate by position too (repeated or collinear corners, as STL files
    // write them): no area to collide with, and ODE's mesh collider crashes
    // on them. Relative to the edges, so tiny meshes keep their triangles.
    const Vec3 e1 = vertices_[tri.v[1]] - vertices_[tri.v[0]];
    const Vec3 e2 = vertices_[tri.v[2]] - vertices_[tri.v[0]];
    const double scale = e1.SquaredNorm() + e2.SquaredNorm();
    if (!(e1.Cross(e2).SquaredNorm() > 1e-24 * scale * scale)) continue;
    origin.push_back(static_cast<uint32_t>(&tri - triangles.data()));
    triangles_.push_back(tri);
  }
  if (triangles_.empty()) throw Error("mesh '" + name_ + "' has no triangles");

  // Bounds and radii over the vertices the triangles use.
  lo_ = {kInf, kInf, kInf};
  hi_ = -lo_;
  for (const MeshTriangle& tri : triangles_)
    for (uint32_t k : tri.v) {
      const Vec3& v = vertices_[k];
      lo_ = Min(lo_, v);
      hi_ = Max(hi_, v);
      footprint_radius_ = std::max(footprint_radius_, std::hypot(v.x, v.y));
      bounding_radius_ = std::max(bounding_radius_, v.Norm());
    }

  // Closed: each directed edge once, and its reverse present. (Sorted
  // edges, from..to in one key: a std::map of 3.9M edges took a second.)
  if (check) check();
  std::vector<uint64_t> edges;
  edges.reserve(3 * triangles_.size());
  for (const MeshTriangle& tri : triangles_)
    for (int k = 0; k < 3; ++k) edges.push_back(uint64_t{tri.v[k]} << 32 | tri.v[(k + 1) % 3]);
  std::sort(edges.begin(), edges.end());
  closed_ = std::adjacent_find(edges.begin(), edges.end()) == edges.end();
  for (size_t i = 0; closed_ && i < edges.size(); ++i)
    closed_ = std::binary_search(edges.begin(), edges.end(), edges[i] << 32 | edges[i] >> 32);
  if (check) check();

  // BVH over the triangles' centroids, median split on the widest axis.
  std::vector<Vec3> centroids;
  centroids.reserve(triangles_.size());
  for (const MeshTriangle& tri : triangles_)
    centroids.push_back((vertices_[tri.v[0]] + vertices_[tri.v[1]] + vertices_[tri.v[2]]) / 3.0);
  nodes_.reserve(2 * triangles_.size() / kLeafTriangles + 1);
  nodes_.emplace_back();
  Build(0, 0, static_cast<uint32_t>(triangles_.size()), &centroids, &origin, check);
  if (!colors.empty()) {
    colors_.reserve(triangles_.size());
    for (uint32_t i : origin) colors_.push_back(colors[i]);
  }
}

void TriangleMesh::Build(uint32_t index, uint32_t first, uint32_t count,
                         std::vector<Vec3>* centroids, std::vector<uint32_t>* origin,
                         const std::function<void()>& check) {
  if (count >= kCheckTriangles && check) check();
  // nodes_ may grow below: always address the node by index.
  Vec3 lo{kInf, kInf, kInf}, hi = -lo, clo = lo, chi = hi;
  for (uint32_t i = first; i < first + count; ++i) {
    for (uint32_t k : triangles_[i].v) lo = Min(lo, vertices_[k]), hi = Max(hi, vertices_[k]);
    clo = Min(clo, (*centroids)[i]);
    chi = Max(chi, (*centroids)[i]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  if (count <= kLeafTriangles) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return;
  }
  const Vec3 extent = chi - clo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  // Sort this range by centroid along the axis (index order breaks ties:
  // the tree does not depend on the sort's implementation).
  std::vector<uint32_t> order(count);
  for (uint32_t i = 0; i < count; ++i) order[i] = first + i;
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const double ca = Axis((*centroids)[a], axis), cb = Axis((*centroids)[b], axis);
    return ca < cb || (ca == cb && a < b);
  });
  std::vector<MeshTriangle> tris(count);
  std::vector<Vec3> cents(count);
  std::vector<uint32_t> origins(count);
  for (uint32_t i = 0; i < count; ++i) {
    tris[i] = triangles_[order[i]];
    cents[i] = (*centroids)[order[i]];
    origins[i] = (*origin)[order[i]];
  }
  std::copy(tris.begin(), tris.end(), triangles_.begin() + first);
  std::copy(cents.begin(), cents.end(), centroids->begin() + first);
  std::copy(origins.begin(), origins.end(), origin->begin() + first);
  // Children are adjacent: left at `left`, right at `left + 1`.
  const uint32_t left = static_cast<uint32_t>(nodes_.size());
  nodes_[index].first = left;
  nodes_[index].count = 0;
  nodes_.emplace_back();
  nodes_.emplace_back();
  const uint32_t half = count / 2;
  Build(left, first, half, centroids, origin, check);
  Build(left + 1, first + half, count - half, centroids, origin, check);
}

bool TriangleMesh::NearestHit(const Vec3& o, const Vec3& d, double max_t, double* t,
                              bool* entering) const {
  double best = kInf;
  bool best_entering = false;
  uint32_t stack[kMaxStack];
  int top = 0;
  if (EnterBox(o, d, nodes_[0], max_t) == kInf) return false;
  stack[top++] = 0;
  while (top > 0) {
    const MeshBvhNode& node = nodes_[stack[--top]];
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        const MeshTriangle& tri = triangles_[i];
        double ti, det;
        if (!RayTriangle(o, d, vertices_[tri.v[0]], vertices_[tri.v[1]], vertices_[tri.v[2]], &ti,
                         &det))
          continue;
        if (ti < 0 || ti > max_t) continue;
        // On a tie (an edge or a vertex) an entering face wins.
        if (ti < best || (ti == best && det > 0 && !best_entering)) {
          best = ti;
          best_entering = det > 0;
        }
      }
      continue;
    }
    const double limit = std::min(max_t, best);
    const double ta = EnterBox(o, d, nodes_[node.first], limit);
    const double tb = EnterBox(o, d, nodes_[node.first + 1], limit);
    // Nearer child on top of the stack.
    const uint32_t near = ta <= tb ? node.first : node.first + 1;
    const uint32_t far = ta <= tb ? node.first + 1 : node.first;
    if (std::max(ta, tb) != kInf) {
      SWARMSIM_CHECK(top < kMaxStack, "mesh BVH deeper than its traversal stack");
      stack[top++] = far;
    }
    if (std::min(ta, tb) != kInf) {
      SWARMSIM_CHECK(top < kMaxStack, "mesh BVH deeper than its traversal stack");
      stack[top++] = near;
    }
  }
  if (best == kInf) return false;
  *t = best;
  *entering = best_entering;
  return true;
}

bool TriangleMesh::RayCast(const Vec3& o, const Vec3& d, double max_t, double* t) const {
  const bool may_be_inside = closed_ && o.x >= lo_.x && o.y >= lo_.y && o.z >= lo_.z &&
                             o.x <= hi_.x && o.y <= hi_.y && o.z <= hi_.z;
  bool entering = false;
  if (!may_be_inside) return NearestHit(o, d, max_t, t, &entering);
  // Inside a closed mesh the nearest face along any ray is left, not entered.
  double hit;
  if (!NearestHit(o, d, kInf, &hit, &entering)) return false;
  if (!entering) {
    *t = 0;
    return true;
  }
  if (hit > max_t) return false;
  *t = hit;
  return true;
}

bool TriangleMesh::AnyTriangleWithin(const Vec3& p, double radius) const {
  const double r2 = radius * radius;
  auto box_distance2 = [&](const MeshBvhNode& n) {
    auto gap = [](double v, double a, double b) { return v < a ? a - v : v > b ? v - b : 0.0; };
    const Vec3 g{gap(p.x, n.lo.x, n.hi.x), gap(p.y, n.lo.y, n.hi.y), gap(p.z, n.lo.z, n.hi.z)};
    return g.SquaredNorm();
  };
  uint32_t stack[kMaxStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const MeshBvhNode& node = nodes_[stack[--top]];
    if (box_distance2(node) > r2) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        const MeshTriangle& tri = triangles_[i];
        const Vec3 c =
            ClosestOnTriangle(p, vertices_[tri.v[0]], vertices_[tri.v[1]], vertices_[tri.v[2]]);
        if ((c - p).SquaredNorm() <= r2) return true;
      }
      continue;
    }
    SWARMSIM_CHECK(top + 2 <= kMaxStack, "mesh BVH deeper than its traversal stack");
    stack[top++] = node.first + 1;
    stack[top++] = node.first;
  }
  return false;
}

Vec3 TriangleMesh::CenteredExtents() const {
  return {2 * std::max(std::abs(lo_.x), std::abs(hi_.x)),
          2 * std::max(std::abs(lo_.y), std::abs(hi_.y)),
          2 * std::max(std::abs(lo_.z), std::abs(hi_.z))};
}

}  // namespace swarmsim
