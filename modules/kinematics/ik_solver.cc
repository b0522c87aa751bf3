#include "modules/kinematics/ik_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <bit>
#include <cmath>

#include "framework/error.h"

namespace swarmsim::kinematics {

namespace {

constexpr int kMaxRows = 6 * kMaxIkElements;
using Jacobian = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxRows, kMaxIkDof>;
using Square = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxRows, kMaxRows>;
using RowVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxRows, 1>;
using ColVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxIkDof, 1>;

// Rotation vector of q (angle * axis), for |angle| <= pi.
Vec3 RotationVector(Quat q) {
  if (q.w < 0) q = {-q.w, -q.x, -q.y, -q.z};
  const Vec3 v{q.x, q.y, q.z};
  const double s = v.Norm();
  if (s < 1e-300) return {};
  return v * (2 * std::atan2(s, q.w) / s);
}

}  // namespace

int IkProblem::AddColumn(const ChainJoint& j) {
  auto it = std::find(slots_.begin(), slots_.end(), j.slot);
  if (it != slots_.end()) return static_cast<int>(it - slots_.begin());
  if (slots_.size() >= kMaxIkDof)
    throw Error("an IK group has at most " + std::to_string(kMaxIkDof) + " joints");
  slots_.push_back(j.slot);
  weights_.push_back(1.0);
  min_.push_back(j.min_position);
  max_.push_back(j.max_position);
  prismatic_.push_back(j.prismatic);
  return static_cast<int>(slots_.size()) - 1;
}

int IkProblem::AddElement(Chain chain, const Pose& X_WTarget, uint8_t constraints) {
  if (elements_.size() >= kMaxIkElements)
    throw Error("an IK group has at most " + std::to_string(kMaxIkElements) + " tip/target pairs");
  Element e;
  e.chain = std::move(chain);
  e.X_WTarget = X_WTarget;
  e.constraints = constraints;
  for (const ChainJoint& j : e.chain.joints()) e.columns.push_back(AddColumn(j));
  elements_.push_back(std::move(e));
  return static_cast<int>(elements_.size()) - 1;
}

int IkProblem::AddClosedElement(Chain tip_chain, Chain target_chain, uint8_t constraints) {
  const int index = AddElement(std::move(tip_chain), Pose{}, constraints);
  Element& e = elements_[index];
  e.closed = true;
  e.target_chain = std::move(target_chain);
  for (const ChainJoint& j : e.target_chain.joints()) e.target_columns.push_back(AddColumn(j));
  return index;
}

void IkProblem::set_base_pose(int element, const Pose& X_WBase) {
  Element& e = elements_.at(element);
  e.chain.set_X_WBase(X_WBase);
  if (e.closed) e.target_chain.set_X_WBase(X_WBase);
}

std::vector<double> IkProblem::ReadPositions(const Scene& scene) const {
  std::vector<double> q;
  for (uint32_t s : slots_) q.push_back(scene.joints()[scene.row_at(s)].position);
  return q;
}

void IkProblem::WritePositions(std::span<const double> q, Scene* scene) const {
  for (size_t i = 0; i < slots_.size(); ++i)
    scene->joints()[scene->row_at(slots_[i])].position = q[i];
}

IkResult IkProblem::Solve(const IkSettings& settings, std::vector<double>* q_io) const {
  const int n = dof();
  SWARMSIM_CHECK(static_cast<int>(q_io->size()) == n, "IK: q has the wrong size");
  int rows = 0;
  for (const Element& e : elements_)
    rows += std::popcount(static_cast<unsigned>(e.constraints & kPose));
  std::vector<double> q = *q_io;
  std::vector<double> q_chain;
  Pose X_WJ[kMaxIkDof], X_WJt[kMaxIkDof];
  Jacobian J(rows, n);
  RowVector err(rows);
  IkResult result;
  const double lambda2 = settings.damping * settings.damping;
  for (int iteration = 0;; ++iteration) {
    // Errors and Jacobian rows, element by element.
    J.setZero();
    int r = 0;
    double worst_p = 0, worst_o = 0;
    for (const Element& e : elements_) {
      const int m = e.chain.dof();
      q_chain.resize(m);
      for (int i = 0; i < m; ++i) q_chain[i] = q[e.columns[i]];
      const Pose X_WTip = e.chain.CalcTipPose(q_chain, X_WJ);
      Pose X_WTarget = e.X_WTarget;
      if (e.closed) {
        const int mt = e.target_chain.dof();
        q_chain.resize(mt);
        for (int i = 0; i < mt; ++i) q_chain[i] = q[e.target_columns[i]];
        X_WTarget = e.target_chain.CalcTipPose(q_chain, X_WJt);
      }
      const Vec3 e_p = X_WTarget.p - X_WTip.p;
      const Quat q_TW = X_WTarget.q.Conjugate();
      // Rotation error in the target frame: turns the tip onto the target.
      const Vec3 e_o = q_TW.Rotate(RotationVector(X_WTarget.q * X_WTip.q.Conjugate()));
      const double ep[3] = {e_p.x, e_p.y, e_p.z}, eo[3] = {e_o.x, e_o.y, e_o.z};
      double norm_p = 0, norm_o = 0;
      for (int k = 0; k < 3; ++k) {
        if (e.constraints & (kX << k)) norm_p += ep[k] * ep[k];
        if (e.constraints & (kAlpha << k)) norm_o += eo[k] * eo[k];
      }
      worst_p = std::max(worst_p, std::sqrt(norm_p));
      worst_o = std::max(worst_o, std::sqrt(norm_o));
      // Columns: revolute a x (p_tip - p_joint) and a; prismatic a and 0.
      for (int i = 0; i < m; ++i) {
        const Vec3 a = X_WJ[i].q.Rotate({0, 0, 1});
        const bool prismatic = prismatic_[e.columns[i]] != 0;
        const Vec3 v = prismatic ? a : a.Cross(X_WTip.p - X_WJ[i].p);
        const Vec3 w = prismatic ? Vec3{} : q_TW.Rotate(a);
        const double vv[3] = {v.x, v.y, v.z}, ww[3] = {w.x, w.y, w.z};
        int row = r;
        for (int k = 0; k < 3; ++k)
          if (e.constraints & (kX << k)) J(row++, e.columns[i]) += vv[k];
        for (int k = 0; k < 3; ++k)
          if (e.constraints & (kAlpha << k)) J(row++, e.columns[i]) += ww[k];
      }
      // Closed chain: the target's joints move the target, so they enter
      // with the opposite sign (the error is target - tip).
      for (int i = 0; e.closed && i < e.target_chain.dof(); ++i) {
        const Vec3 a = X_WJt[i].q.Rotate({0, 0, 1});
        const bool prismatic = prismatic_[e.target_columns[i]] != 0;
        const Vec3 v = prismatic ? a : a.Cross(X_WTarget.p - X_WJt[i].p);
        const Vec3 w = prismatic ? Vec3{} : q_TW.Rotate(a);
        const double vv[3] = {v.x, v.y, v.z}, ww[3] = {w.x, w.y, w.z};
        int row = r;
        for (int k = 0; k < 3; ++k)
          if (e.constraints & (kX << k)) J(row++, e.target_columns[i]) -= vv[k];
        for (int k = 0; k < 3; ++k)
          if (e.constraints & (kAlpha << k)) J(row++, e.target_columns[i]) -= ww[k];
      }
      for (int k = 0; k < 3; ++k)
        if (e.constraints & (kX << k)) err(r++) = ep[k];
      for (int k = 0; k < 3; ++k)
        if (e.constraints & (kAlpha << k)) err(r++) = eo[k];
    }
    result.iterations = iteration;
    result.position_error = worst_p;
    result.orientation_error = worst_o;
    if (worst_p <= settings.position_tolerance && worst_o <= settings.orientation_tolerance) {
      result.solved = true;
      break;
    }
    if (iteration >= settings.max_iterations) break;
    // Damped least squares step, weighted, clamped.
    ColVector weights(n);
    for (int i = 0; i < n; ++i) weights(i) = weights_[i];
    const Jacobian JW = J * weights.asDiagonal();
    Square A = JW * J.transpose();
    A.diagonal().array() += lambda2;
    const RowVector y = A.ldlt().solve(err);
    const ColVector dq = JW.transpose() * y;
    for (int i = 0; i < n; ++i) {
      const double step = std::clamp(dq(i), -settings.max_step, settings.max_step);
      q[i] = std::clamp(q[i] + step, min_[i], max_[i]);
    }
  }
  if (result.solved || !settings.apply_only_when_solved) *q_io = q;
  return result;
}

}  // namespace swarmsim::kinematics
