#include "modules/paths/curve.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace swarmsim::paths {

namespace {

// Samples of the arc-length table per smooth segment; each sample interval
// is integrated with 5-point Gauss-Legendre (relative error ~1e-12 on a
// cubic's speed).
constexpr int kSamples = 32;

constexpr double kGaussX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                               0.9061798459386640};
constexpr double kGaussW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                               0.4786286704993665, 0.2369268850561891};

}  // namespace

Quat FromAxes(const Vec3& x, const Vec3& y, const Vec3& z) {
  const double trace = x.x + y.y + z.z;
  Quat q;
  if (trace > 0) {
    const double s = std::sqrt(trace + 1.0) * 2;
    q = {0.25 * s, (y.z - z.y) / s, (z.x - x.z) / s, (x.y - y.x) / s};
  } else if (x.x > y.y && x.x > z.z) {
    const double s = std::sqrt(1.0 + x.x - y.y - z.z) * 2;
    q = {(y.z - z.y) / s, 0.25 * s, (y.x + x.y) / s, (z.x + x.z) / s};
  } else if (y.y > z.z) {
    const double s = std::sqrt(1.0 + y.y - x.x - z.z) * 2;
    q = {(z.x - x.z) / s, (y.x + x.y) / s, 0.25 * s, (z.y + y.z) / s};
  } else {
    const double s = std::sqrt(1.0 + z.z - x.x - y.y) * 2;
    q = {(x.y - y.x) / s, (z.x + x.z) / s, (z.y + y.z) / s, 0.25 * s};
  }
  return q.Normalized();
}

Quat Slerp(const Quat& a, const Quat& b_in, double f) {
  Quat b = b_in;
  double cosine = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  if (cosine < 0) {
    b = {-b.w, -b.x, -b.y, -b.z};
    cosine = -cosine;
  }
  double ka = 1 - f, kb = f;
  if (cosine < 0.9999) {  // else nearly equal: linear, normalized below
    const double angle = std::acos(std::min(cosine, 1.0));
    const double s = std::sin(angle);
    ka = std::sin((1 - f) * angle) / s;
    kb = std::sin(f * angle) / s;
  }
  return Quat{ka * a.w + kb * b.w, ka * a.x + kb * b.x, ka * a.y + kb * b.y, ka * a.z + kb * b.z}
      .Normalized();
}

PathCurve::PathCurve(std::vector<Vec3> points, Interpolation interpolation, bool closed,
                     std::vector<Quat> orientations)
    : PathCurve(std::move(points), interpolation, closed) {
  if (orientations.size() == points_.size()) orientations_ = std::move(orientations);
}

PathCurve::PathCurve(std::vector<Vec3> points, Interpolation interpolation, bool closed)
    : points_(std::move(points)), interpolation_(interpolation), closed_(closed) {
  const size_t n = segments();
  segment_start_.assign(n + 1, 0.0);
  if (interpolation_ == Interpolation::kSmooth) table_.assign(n * (kSamples + 1), 0.0);
  for (size_t i = 0; i < n; ++i) {
    double len = 0;
    if (interpolation_ == Interpolation::kLinear) {
      len = (points_[(i + 1) % points_.size()] - points_[i]).Norm();
    } else {
      double* row = &table_[i * (kSamples + 1)];
      for (int k = 0; k < kSamples; ++k)
        row[k + 1] = row[k] + SmoothLength(i, double(k) / kSamples, double(k + 1) / kSamples);
      len = row[kSamples];
    }
    segment_start_[i + 1] = segment_start_[i] + len;
  }
  length_ = segment_start_[n];
}

double PathCurve::Normalize(double s) const {
  if (closed_) {
    s = std::fmod(s, length_);
    if (s < 0) s += length_;
    return s >= length_ ? 0.0 : s;
  }
  return std::clamp(s, 0.0, length_);
}

void PathCurve::Controls(size_t i, Vec3 c[4]) const {
  const size_t n = points_.size();
  c[1] = points_[i];
  c[2] = points_[(i + 1) % n];
  if (closed_) {
    c[0] = points_[(i + n - 1) % n];
    c[3] = points_[(i + 2) % n];
  } else {
    // Open ends: the first and last points mirrored (straight-ish ends).
    c[0] = i > 0 ? points_[i - 1] : c[1] * 2.0 - c[2];
    c[3] = i + 2 < n ? points_[i + 2] : c[2] * 2.0 - c[1];
  }
}

Vec3 PathCurve::Position(size_t i, double t) const {
  if (interpolation_ == Interpolation::kLinear) {
    const Vec3& a = points_[i];
    const Vec3& b = points_[(i + 1) % points_.size()];
    return a + (b - a) * t;
  }
  Vec3 c[4];
  Controls(i, c);
  const Vec3 a1 = c[2] - c[0];
  const Vec3 a2 = c[0] * 2.0 - c[1] * 5.0 + c[2] * 4.0 - c[3];
  const Vec3 a3 = c[1] * 3.0 - c[0] - c[2] * 3.0 + c[3];
  return c[1] + (a1 * t + a2 * (t * t) + a3 * (t * t * t)) * 0.5;
}

Vec3 PathCurve::Derivative(size_t i, double t) const {
  if (interpolation_ == Interpolation::kLinear)
    return points_[(i + 1) % points_.size()] - points_[i];
  Vec3 c[4];
  Controls(i, c);
  const Vec3 a1 = c[2] - c[0];
  const Vec3 a2 = c[0] * 2.0 - c[1] * 5.0 + c[2] * 4.0 - c[3];
  const Vec3 a3 = c[1] * 3.0 - c[0] - c[2] * 3.0 + c[3];
  return (a1 + a2 * (2 * t) + a3 * (3 * t * t)) * 0.5;
}

double PathCurve::SmoothLength(size_t i, double t0, double t1) const {
  const double half = (t1 - t0) / 2, mid = (t0 + t1) / 2;
  double sum = 0;
  for (int g = 0; g < 5; ++g) sum += kGaussW[g] * Derivative(i, mid + half * kGaussX[g]).Norm();
  return sum * half;
}

Pose PathCurve::PoseAt(double s) const {
  s = Normalize(s);
  // The segment holding s (the later one at a shared end, but the last at the end).
  const size_t n = segments();
  size_t i = static_cast<size_t>(std::upper_bound(segment_start_.begin(), segment_start_.end(), s) -
                                 segment_start_.begin());
  i = std::min(i == 0 ? 0 : i - 1, n - 1);
  const double local = s - segment_start_[i];
  const double seg_len = segment_start_[i + 1] - segment_start_[i];
  double t = 0;
  if (interpolation_ == Interpolation::kLinear) {
    t = std::clamp(local / seg_len, 0.0, 1.0);
  } else {
    // The table's interval, then Newton on the length from its start
    // (bisection-guarded).
    const double* row = &table_[i * (kSamples + 1)];
    int k = static_cast<int>(std::upper_bound(row, row + kSamples + 1, local) - row) - 1;
    k = std::clamp(k, 0, kSamples - 1);
    double lo = double(k) / kSamples, hi = double(k + 1) / kSamples;
    const double target = local - row[k];
    const double span = row[k + 1] - row[k];
    t = lo + (span > 0 ? target / span : 0) * (hi - lo);
    for (int iter = 0; iter < 20; ++iter) {
      const double f = SmoothLength(i, double(k) / kSamples, t) - target;
      if (std::abs(f) < 1e-13) break;
      if (f > 0)
        hi = t;
      else
        lo = t;
      const double speed = Derivative(i, t).Norm();
      double next = speed > 0 ? t - f / speed : (lo + hi) / 2;
      if (!(next > lo && next < hi)) next = (lo + hi) / 2;
      t = next;
    }
  }
  if (!orientations_.empty()) {
    const double f = seg_len > 0 ? std::clamp(local / seg_len, 0.0, 1.0) : 0.0;
    return {Position(i, t), Slerp(orientations_[i], orientations_[(i + 1) % points_.size()], f)};
  }
  Vec3 x = Derivative(i, t).Normalized();
  if (x.SquaredNorm() == 0) x = (points_[(i + 1) % points_.size()] - points_[i]).Normalized();
  Vec3 z = Vec3{0, 0, 1} - x * x.z;
  if (z.SquaredNorm() < 1e-12) z = Vec3{0, 1, 0} - x * x.y;  // a vertical tangent
  z = z.Normalized();
  const Vec3 y = z.Cross(x);
  return {Position(i, t), FromAxes(x, y, z)};
}

}  // namespace swarmsim::paths
