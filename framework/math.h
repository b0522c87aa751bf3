// Small value types for poses: Vec3, Quat, Pose.
//
// Deliberately tiny and header-only: these are in every hot loop and every
// header, and Eigen's expression templates would cost build time everywhere.
// Heavy linear algebra (IK, least squares) uses Eigen inside its module.
//
// Frames follow Drake's notation: X_AB is the pose of frame B in frame A,
// p_AB the position of B's origin in A, and X_AC = X_AB * X_BC.
#pragma once

#include <cmath>

namespace swarmsim {

// Largest length or coordinate a world may use, m (world files, scripts'
// moves): keeps geometry and grids far from overflow, and within what the
// physics engines handle (Box2D works in float; ODE aborts on huge AABBs).
inline constexpr double kMaxCoordinate = 1e6;

struct Vec3 {  // 24 bytes
  double x = 0, y = 0, z = 0;

  constexpr Vec3() = default;
  constexpr Vec3(double x_in, double y_in, double z_in) : x(x_in), y(y_in), z(z_in) {}

  constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
  Vec3& operator+=(const Vec3& o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  Vec3& operator-=(const Vec3& o) {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  constexpr bool operator==(const Vec3& o) const = default;

  constexpr double Dot(const Vec3& o) const { return x * o.x + y * o.y + z * o.z; }
  constexpr Vec3 Cross(const Vec3& o) const {
    return {y * o.z - z * o.y, z * o.x - x * o.z, x * o.y - y * o.x};
  }
  constexpr double SquaredNorm() const { return Dot(*this); }
  double Norm() const { return std::sqrt(SquaredNorm()); }
  Vec3 Normalized() const {
    const double n = Norm();
    return n > 0 ? *this / n : Vec3{};
  }
};

// Whether p lies within kMaxCoordinate on every axis (false for NaN).
inline bool WithinWorld(const Vec3& p) {
  return std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate &&
         std::abs(p.z) <= kMaxCoordinate;
}

constexpr Vec3 operator*(double s, const Vec3& v) { return v * s; }

// Unit quaternion (w, x, y, z) for rotations.
struct Quat {  // 32 bytes
  double w = 1, x = 0, y = 0, z = 0;

  static Quat FromAxisAngle(const Vec3& axis, double angle) {
    const Vec3 a = axis.Normalized();
    const double s = std::sin(angle / 2);
    return {std::cos(angle / 2), a.x * s, a.y * s, a.z * s};
  }
  // Rotation about world z by `yaw` (heading in the plane).
  static Quat FromYaw(double yaw) { return {std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)}; }
  // Extrinsic roll (x), pitch (y), yaw (z): R = Rz(yaw) * Ry(pitch) * Rx(roll).
  static Quat FromRollPitchYaw(double roll, double pitch, double yaw) {
    return FromAxisAngle({0, 0, 1}, yaw) * FromAxisAngle({0, 1, 0}, pitch) *
           FromAxisAngle({1, 0, 0}, roll);
  }

  constexpr Quat operator*(const Quat& o) const {
    return {w * o.w - x * o.x - y * o.y - z * o.z, w * o.x + x * o.w + y * o.z - z * o.y,
            w * o.y - x * o.z + y * o.w + z * o.x, w * o.z + x * o.y - y * o.x + z * o.w};
  }
  constexpr Quat Conjugate() const { return {w, -x, -y, -z}; }
  constexpr bool operator==(const Quat& o) const = default;

  // Rotates v: q * v * q^-1, expanded (t = 2 q_v x v; v' = v + w t + q_v x t).
  constexpr Vec3 Rotate(const Vec3& v) const {
    const Vec3 q{x, y, z};
    const Vec3 t = q.Cross(v) * 2.0;
    return v + t * w + q.Cross(t);
  }
  Quat Normalized() const {
    const double n = std::sqrt(w * w + x * x + y * y + z * z);
    return n > 0 ? Quat{w / n, x / n, y / n, z / n} : Quat{};
  }
  // Heading: rotation about z of the rotated x axis, in (-pi, pi].
  double Yaw() const { return std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)); }
  // Roll, pitch, yaw matching FromRollPitchYaw.
  Vec3 RollPitchYaw() const {
    const double sinp = 2 * (w * y - z * x);
    const double pitch = std::abs(sinp) >= 1 ? std::copysign(M_PI / 2, sinp) : std::asin(sinp);
    return {std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)), pitch, Yaw()};
  }
};

// Rigid transform X_AB: rotation q_AB then translation p_AB.
struct Pose {  // 56 bytes
  Vec3 p;
  Quat q;

  constexpr Pose operator*(const Pose& X_BC) const { return {p + q.Rotate(X_BC.p), q * X_BC.q}; }
  constexpr Vec3 operator*(const Vec3& p_BC) const { return p + q.Rotate(p_BC); }
  constexpr Pose Inverse() const {
    const Quat qi = q.Conjugate();
    return {qi.Rotate(-p), qi};
  }
  constexpr bool operator==(const Pose& o) const = default;
};

}  // namespace swarmsim
