// A path's curve (paper §2.1): control points in the path's frame joined
// by straight segments or a uniform Catmull-Rom spline through them, open
// or closed, parametrised by arc length s through a dense table built once
// (immutable: copies of a model share it). Internal to modules/paths.
#pragma once

#include <cstddef>
#include <vector>

#include "framework/math.h"

namespace swarmsim::paths {

// The rotation whose columns are the orthonormal axes x, y, z.
Quat FromAxes(const Vec3& x, const Vec3& y, const Vec3& z);
// Spherical linear interpolation from a (f = 0) to b (f = 1), the short way.
Quat Slerp(const Quat& a, const Quat& b, double f);

enum class Interpolation { kLinear, kSmooth };

class PathCurve {
 public:
  // `points`: at least 2, no two consecutive ones equal (nor the last and the
  // first of a closed curve); the reader checks it.
  PathCurve(std::vector<Vec3> points, Interpolation interpolation, bool closed);
  // The same with an orientation per point (in the path's frame, one per
  // point, or none): PoseAt then turns from each point's orientation to the
  // next one's (slerp, by arc length) instead of following the tangent.
  PathCurve(std::vector<Vec3> points, Interpolation interpolation, bool closed,
            std::vector<Quat> orientations);

  double length() const { return length_; }
  bool closed() const { return closed_; }
  Interpolation interpolation() const { return interpolation_; }
  const std::vector<Vec3>& points() const { return points_; }
  // The points' orientations, or empty (the tangent frame).
  const std::vector<Quat>& orientations() const { return orientations_; }
  // s clamped into [0, length] (open) or wrapped into [0, length) (closed).
  double Normalize(double s) const;
  // X_PC: the pose at arc length s (normalized) in the path's frame: the
  // origin on the curve, x along the tangent, z as near the path's z as the
  // tangent allows (or, with orientations, the slerp between the segment's
  // two points' orientations, by arc length).
  Pose PoseAt(double s) const;
  // The arc length of control point i (it lies on the curve).
  double LengthAtPoint(size_t i) const { return segment_start_[i]; }
  // Bytes it holds beyond its own size (its arrays).
  size_t HeldBytes() const {
    return points_.capacity() * sizeof(Vec3) + orientations_.capacity() * sizeof(Quat) +
           (segment_start_.capacity() + table_.capacity()) * sizeof(double);
  }

 private:
  size_t segments() const { return closed_ ? points_.size() : points_.size() - 1; }
  // The segment's four Catmull-Rom control points.
  void Controls(size_t segment, Vec3 c[4]) const;
  Vec3 Position(size_t segment, double t) const;
  Vec3 Derivative(size_t segment, double t) const;
  // Arc length of a smooth segment from t0 to t1 (5-point Gauss-Legendre).
  double SmoothLength(size_t segment, double t0, double t1) const;

  std::vector<Vec3> points_;
  std::vector<Quat> orientations_;  // (points) or empty
  Interpolation interpolation_;
  bool closed_;
  std::vector<double> segment_start_;  // arc length at each segment's start (segments + 1)
  std::vector<double> table_;          // smooth: arc length at t = k / kSamples of each segment
  double length_ = 0;
};

}  // namespace swarmsim::paths
