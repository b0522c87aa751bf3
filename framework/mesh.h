// Triangle meshes: an immutable asset (vertices, triangles, bounds and a
// bounding-volume hierarchy over the triangles), built once per file and
// scale by the loader and shared, through std::shared_ptr<const TriangleMesh>,
// by every shape and every copy that uses it (DESIGN.md: copies cost rows,
// not assets).
//
// Plain arrays only: file formats (STL, OBJ through assimp) stay in the
// loader. Coordinates are metres in the shape's frame, scale already applied.
//
// Solid or surface. A mesh is *closed* when every edge is shared by exactly
// two triangles that run it in opposite directions (a consistently wound,
// watertight surface). A closed mesh is a solid, outward normals by the
// right-hand rule (counter-clockwise seen from outside, as STL and OBJ
// expect): a ray that starts inside hits it at t = 0, like every other
// shape. An open mesh is a surface: rays hit its triangles from either side.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "framework/math.h"

namespace swarmsim {

struct MeshTriangle {  // 12 bytes
  uint32_t v[3];       // vertex indices, counter-clockwise seen from outside
};

// A BVH node: a box around triangles [first, first + count) (a leaf), or
// around its children `first` and `first + 1` (count == 0).
struct MeshBvhNode {  // 56 bytes
  Vec3 lo, hi;
  uint32_t first;
  uint32_t count;
};

// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision
// Detection, 5.1.5).
Vec3 ClosestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

class TriangleMesh {
 public:
  // Builds the asset and its BVH. Throws swarmsim::Error (naming `name`) for
  // no triangles, an index out of range or a non-finite vertex. Triangles
  // whose corners coincide are dropped; the others are reordered by the BVH.
  // `colors`: none, or one RGB (0..1) per triangle, the file's materials
  // (they follow their triangles). `check`, if given, is called now and
  // then while a large mesh is built (seconds at a million triangles); it
  // may throw to abandon the build (the loader's stop signals).
  TriangleMesh(std::string name, std::vector<Vec3> vertices, std::vector<MeshTriangle> triangles,
               std::vector<Vec3> colors = {}, const std::function<void()>& check = {});

  const std::string& name() const { return name_; }  // the file, for messages
  std::span<const Vec3> vertices() const { return vertices_; }
  std::span<const MeshTriangle> triangles() const { return triangles_; }
  std::span<const MeshBvhNode> bvh() const { return nodes_; }
  // One RGB per triangle (triangles' order), or empty: the file had no materials.
  std::span<const Vec3> colors() const { return colors_; }
  const Vec3& lo() const { return lo_; }  // bounds of the vertices
  const Vec3& hi() const { return hi_; }
  bool closed() const { return closed_; }
  // Largest distance of a vertex from the frame's z axis, and from its origin.
  double footprint_radius() const { return footprint_radius_; }
  double bounding_radius() const { return bounding_radius_; }
  // Full extents of the smallest box centred on the frame's origin that
  // holds the mesh (what ShapeData::size holds for a mesh).
  Vec3 CenteredExtents() const;

  // Nearest hit of the ray o + t d (d unit, mesh frame), t in [0, max_t],
  // exact to the triangles (Moller-Trumbore, double precision). A ray that
  // starts inside a closed mesh hits at t = 0.
  bool RayCast(const Vec3& o, const Vec3& d, double max_t, double* t) const;
  // Does some triangle come within `radius` of the point p (mesh frame)?
  bool AnyTriangleWithin(const Vec3& p, double radius) const;

 private:
  // Fills node `index` with triangles [first, first + count) and its subtree.
  // `origin`: each triangle's index in the constructor's list, reordered alike.
  // `check` (may be empty) is called at each node of kCheckTriangles or more.
  void Build(uint32_t index, uint32_t first, uint32_t count, std::vector<Vec3>* centroids,
             std::vector<uint32_t>* origin, const std::function<void()>& check);
  // Nearest triangle hit in (0 <= t <= max_t); *entering: the ray enters there.
  bool NearestHit(const Vec3& o, const Vec3& d, double max_t, double* t, bool* entering) const;

  std::string name_;
  std::vector<Vec3> vertices_;           // (vertices)
  std::vector<MeshTriangle> triangles_;  // (triangles), BVH order
  std::vector<Vec3> colors_;             // (triangles) or empty
  std::vector<MeshBvhNode> nodes_;       // (nodes), root first
  Vec3 lo_, hi_;
  bool closed_ = false;
  double footprint_radius_ = 0;
  double bounding_radius_ = 0;
};

}  // namespace swarmsim
