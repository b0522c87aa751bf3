// Mass properties of URDF links and bodies (urdf_inertia.h).
#include "swarm/loader/urdf_inertia.h"

#include <algorithm>
#include <cmath>

namespace swarmsim::loader {

namespace {

using Matrix = std::array<std::array<double, 3>, 3>;

Matrix ToMatrix(const Inertia& i) {
  return {{{i[0], i[3], i[4]}, {i[3], i[1], i[5]}, {i[4], i[5], i[2]}}};
}

Inertia FromMatrix(const Matrix& m) {
  // Symmetrised: R I R^T is symmetric up to rounding.
  return {m[0][0],
          m[1][1],
          m[2][2],
          0.5 * (m[0][1] + m[1][0]),
          0.5 * (m[0][2] + m[2][0]),
          0.5 * (m[1][2] + m[2][1])};
}

}  // namespace

MassProperties Transformed(const MassProperties& part, const Pose& X_BA) {
  MassProperties out;
  out.mass = part.mass;
  out.center = X_BA * part.center;
  // R's columns are A's axes in B.
  Matrix R;
  for (int c = 0; c < 3; ++c) {
    const Vec3 col = X_BA.q.Rotate({c == 0 ? 1.0 : 0.0, c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0});
    R[0][c] = col.x, R[1][c] = col.y, R[2][c] = col.z;
  }
  const Matrix I = ToMatrix(part.inertia);
  Matrix J{};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) J[a][b] += R[a][k] * I[k][l] * R[b][l];
  out.inertia = FromMatrix(J);
  return out;
}

void AddMass(const MassProperties& part, MassProperties* sum) {
  if (!(part.mass > 0)) return;
  const double mass = sum->mass + part.mass;
  const Vec3 center = (sum->center * sum->mass + part.center * part.mass) / mass;
  // Each about the new centre: I + m (|d|^2 E - d d^T).
  auto shifted = [&](const MassProperties& p) {
    const Vec3 d = p.center - center;
    const double m = p.mass, d2 = d.SquaredNorm();
    Inertia i = p.inertia;
    i[0] += m * (d2 - d.x * d.x);
    i[1] += m * (d2 - d.y * d.y);
    i[2] += m * (d2 - d.z * d.z);
    i[3] -= m * d.x * d.y;
    i[4] -= m * d.x * d.z;
    i[5] -= m * d.y * d.z;
    return i;
  };
  const Inertia a = sum->mass > 0 ? shifted(*sum) : Inertia{};
  const Inertia b = shifted(part);
  for (int k = 0; k < 6; ++k) sum->inertia[k] = a[k] + b[k];
  sum->mass = mass;
  sum->center = center;
}

std::array<double, 3> PrincipalMoments(const Inertia& inertia) {
  // Cyclic Jacobi rotations: exact for symmetric 3x3 to rounding.
  Matrix A = ToMatrix(inertia);
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = A[0][1] * A[0][1] + A[0][2] * A[0][2] + A[1][2] * A[1][2];
    const double diag = A[0][0] * A[0][0] + A[1][1] * A[1][1] + A[2][2] * A[2][2];
    if (off <= 1e-30 * diag || off == 0) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (A[p][q] == 0) continue;
        const double theta = (A[q][q] - A[p][p]) / (2 * A[p][q]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        // A <- J^T A J, J the rotation in the (p, q) plane.
        for (int k = 0; k < 3; ++k) {
          const double akp = A[k][p], akq = A[k][q];
          A[k][p] = c * akp - s * akq;
          A[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const double apk = A[p][k], aqk = A[q][k];
          A[p][k] = c * apk - s * aqk;
          A[q][k] = s * apk + c * aqk;
        }
      }
  }
  std::array<double, 3> moments{A[0][0], A[1][1], A[2][2]};
  std::sort(moments.begin(), moments.end());
  return moments;
}

bool InertiaIsPhysical(const Inertia& inertia) {
  for (double v : inertia)
    if (!std::isfinite(v)) return false;
  const auto [small, middle, large] = PrincipalMoments(inertia);
  if (!(large > 0) || !(small > kMinMomentRatio * large)) return false;
  return large <= small + middle + 1e-9 * (small + middle + large);
}

Inertia BalancedInertia(const Inertia& inertia) {
  const double mean = (inertia[0] + inertia[1] + inertia[2]) / 3;
  return {mean, mean, mean, 0, 0, 0};
}

}  // namespace swarmsim::loader
