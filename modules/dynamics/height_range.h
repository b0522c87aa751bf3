// Heights of shapes, for the engines' rule of which static geometry the
// dynamic shapes can meet: a static shape (or a voxel of the environment
// map) is an obstacle if it reaches more than kHeightOverlap into the
// height range of the dynamic shapes (a floor whose top touches the robots'
// bottom is not one). Engine-neutral.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/scene.h"

namespace swarmsim::dynamics {

// How far a static shape must reach into the dynamic shapes' height range, m.
inline constexpr double kHeightOverlap = 1e-3;

// Height range [lo, hi] of shapes, m.
struct HeightRange {
  double lo, hi;
};

// Does a static shape of heights `range` reach into the dynamic shapes'
// `dynamic` range: is it an obstacle?
inline bool ReachesInto(const HeightRange& range, const HeightRange& dynamic) {
  return range.hi > dynamic.lo + kHeightOverlap && range.lo < dynamic.hi - kHeightOverlap;
}

// Height range of a shape at pose X_WS, m.
inline HeightRange CalcHeightRange(const ShapeData& shape, const Pose& X_WS) {
  const double z = X_WS.p.z;
  if (shape.kind == ShapeKind::kMesh && shape.mesh) {  // exact over the vertices
    HeightRange range{std::numeric_limits<double>::infinity(),
                      -std::numeric_limits<double>::infinity()};
    for (const Vec3& v : shape.mesh->vertices()) {
      const double vz = (X_WS * v).z;
      range = {std::min(range.lo, vz), std::max(range.hi, vz)};
    }
    return range;
  }
  if (shape.kind == ShapeKind::kSphere) return {z - shape.size.x, z + shape.size.x};
  // Half extents along the shape's axes; the vertical extent is the sum of
  // their projections on world z.
  const Vec3 half = shape.kind == ShapeKind::kBox
                        ? shape.size * 0.5
                        : Vec3{shape.size.x, shape.size.x, shape.size.z * 0.5};
  const Vec3 ax = X_WS.q.Rotate({1, 0, 0}), ay = X_WS.q.Rotate({0, 1, 0}),
             az = X_WS.q.Rotate({0, 0, 1});
  double h;
  if (shape.kind == ShapeKind::kBox) {
    h = half.x * std::abs(ax.z) + half.y * std::abs(ay.z) + half.z * std::abs(az.z);
  } else {  // cylinder: the axis part plus the disc's radius across
    h = half.z * std::abs(az.z) + shape.size.x * std::sqrt(std::max(0.0, 1 - az.z * az.z));
  }
  return {z - h, z + h};
}

// The height range of every live dynamic shape ({inf, -inf} when none).
inline HeightRange DynamicHeightRange(const Scene& scene) {
  HeightRange range{std::numeric_limits<double>::infinity(),
                    -std::numeric_limits<double>::infinity()};
  const auto shapes = scene.shapes();
  const auto owners = scene.shape_owners();
  for (size_t r = 0; r < shapes.size(); ++r) {
    if (!shapes[r].dynamic || !scene.alive_at(owners[r])) continue;
    const HeightRange h = CalcHeightRange(shapes[r], scene.world_pose_at(owners[r]));
    range = {std::min(range.lo, h.lo), std::max(range.hi, h.hi)};
  }
  return range;
}

}  // namespace swarmsim::dynamics
