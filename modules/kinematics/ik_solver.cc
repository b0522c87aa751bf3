#include "modules/kinematics/ik_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "framework/error.h"

namespace swarmsim::kinematics {

namespace {

constexpr int kMaxRows = 6 * kMaxIkElements + kMaxIkAvoidLinks;
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

// The rotation of rotation vector v.
Quat FromRotationVector(const Vec3& v) {
  const double angle = v.Norm();
  if (angle < 1e-300) return {};
  return Quat::FromAxisAngle(v, angle);
}

}  // namespace

int IkProblem::AddColumn(const ChainJoint& j) {
  auto it = std::find(slots_.begin(), slots_.end(), j.slot);
  if (it != slots_.end()) return static_cast<int>(it - slots_.begin());
  const bool ball = j.kind == ChainJointKind::kSpherical;
  if (slots_.size() + (ball ? 3 : 1) > kMaxIkDof)
    throw Error("an IK group has at most " + std::to_string(kMaxIkDof) +
                " unknowns (a spherical joint counts 3)");
  const int first = static_cast<int>(slots_.size());
  for (int k = 0; k < (ball ? 3 : 1); ++k) {
    slots_.push_back(j.slot);
    weights_.push_back(1.0);
    min_.push_back(ball ? -INFINITY : j.min_position);
    max_.push_back(ball ? INFINITY : j.max_position);
    kind_.push_back(static_cast<uint8_t>(ball ? kBallX + k : kOne));
    frozen_.push_back(0);
    master_.push_back(-1);
    factor_.push_back(1);
    offset_.push_back(0);
    ball0_.push_back(j.ball);
  }
  return first;
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

int IkProblem::AddAvoidLink(Chain link_chain, double clearance) {
  if (avoid_.size() >= kMaxIkAvoidLinks)
    throw Error("an IK group avoids obstacles with at most " + std::to_string(kMaxIkAvoidLinks) +
                " links");
  AvoidLink a;
  a.chain = std::move(link_chain);
  a.clearance = clearance;
  for (const ChainJoint& j : a.chain.joints()) a.columns.push_back(AddColumn(j));
  avoid_.push_back(std::move(a));
  return static_cast<int>(avoid_.size()) - 1;
}

void IkProblem::SetDependent(int column, int master, double factor, double offset) {
  SWARMSIM_CHECK(kind_.at(column) == kOne && kind_.at(master) == kOne && master_[master] < 0,
                 "IK: a dependent column follows a one-column independent master");
  master_[column] = master;
  factor_[column] = factor;
  offset_[column] = offset;
}

void IkProblem::set_base_pose(int element, const Pose& X_WBase) {
  Element& e = elements_.at(element);
  e.chain.set_X_WBase(X_WBase);
  if (e.closed) e.target_chain.set_X_WBase(X_WBase);
}

std::vector<double> IkProblem::ReadPositions(const Scene& scene) const {
  std::vector<double> q;
  for (size_t c = 0; c < slots_.size(); ++c)
    q.push_back(kind_[c] == kOne ? scene.joints()[scene.row_at(slots_[c])].position : 0.0);
  return q;
}

void IkProblem::WritePositions(std::span<const double> q, Scene* scene) const {
  for (size_t c = 0; c < slots_.size(); ++c)
    if (kind_[c] == kOne) scene->joints()[scene->row_at(slots_[c])].position = q[c];
}

IkResult IkProblem::Solve(const IkSettings& settings, std::vector<double>* q_io,
                          std::vector<Quat>* ball_io) const {
  const int n = dof();
  SWARMSIM_CHECK(static_cast<int>(q_io->size()) == n, "IK: q has the wrong size");
  SWARMSIM_CHECK(ball_io == nullptr || static_cast<int>(ball_io->size()) == n,
                 "IK: ball has the wrong size");
  int target_rows = 0;
  for (const Element& e : elements_)
    target_rows += std::popcount(static_cast<unsigned>(e.constraints & kPose));
  std::vector<double> q = *q_io;
  std::vector<Quat> ball = ball_io != nullptr ? *ball_io : ball0_;
  // Dependent columns start on their formula.
  for (int c = 0; c < n; ++c)
    if (master_[c] >= 0) q[c] = offset_[c] + factor_[c] * q[master_[c]];
  std::vector<double> q_chain;
  std::vector<Quat> ball_chain;
  Pose X_WJ[kMaxIkDof], X_WJt[kMaxIkDof];
  // Each avoidance link's witness point in the link frame.
  Vec3 p_L[kMaxIkAvoidLinks];
  for (size_t a = 0; a < avoid_.size(); ++a)
    p_L[a] = avoid_[a].reading.X_WLink.Inverse() * avoid_[a].reading.p_WL;
  Jacobian J(target_rows + static_cast<int>(avoid_.size()), n);
  RowVector err(target_rows + static_cast<int>(avoid_.size()));
  IkResult result;
  // Levenberg-Marquardt damping: a step that leaves the error larger than
  // it found it is taken back and tried again damped 10x more; a step that
  // helps lets the damping fall back towards settings.damping. So the error
  // never grows from one iterate to the next (a target out of reach: the
  // mechanism turns towards it and stays, instead of swinging about the
  // singular stretched pose), and steps that help are taken as before.
  // (Problems with avoidance links step undamped by this: a link's row that
  // turns on adds error by design.)
  const double lambda2_min = settings.damping * settings.damping;
  double lambda2 = lambda2_min;
  constexpr double kDampingGrowth = 100;  // on lambda^2: 10x on lambda
  double last_cost = std::numeric_limits<double>::infinity();
  std::vector<double> q_last;
  std::vector<Quat> ball_last;
  IkResult last_result;
  Jacobian J_last;
  RowVector err_last;
  int r_last = 0;

  // The chain's joint values (q per joint, balls) from the columns.
  const auto chain_values = [&](const Chain& chain, const std::vector<int>& columns) {
    const int m = chain.dof();
    q_chain.resize(m);
    ball_chain.resize(m);
    for (int i = 0; i < m; ++i) {
      q_chain[i] = q[columns[i]];
      ball_chain[i] = ball[columns[i]];
    }
  };
  // Adds sign * d(point, rotation)/dq of the chain's joints to out's rows
  // from `row` (the constraint subset `bits`); a dependent joint's column
  // folds into its master's.
  const auto add_columns = [&](const Chain& chain, const std::vector<int>& columns,
                               const Pose* X_WJs, const Vec3& p_W, const Quat& q_TW, uint8_t bits,
                               int row, double sign, Jacobian* out) {
    for (int i = 0; i < chain.dof(); ++i) {
      const ChainJoint& joint = chain.joints()[i];
      const Vec3 r = p_W - X_WJs[i].p;
      int column = columns[i];
      double scale = sign;
      if (master_[column] >= 0) {
        scale *= factor_[column];
        column = master_[column];
      }
      const bool ball = joint.kind == ChainJointKind::kSpherical;
      for (int k = ball ? 0 : 2; k < 3; ++k) {
        // Revolute, prismatic, screw: about/along z; spherical: x, y and z.
        const Vec3 a =
            X_WJs[i].q.Rotate({k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0});
        Vec3 v = a.Cross(r), w = q_TW.Rotate(a);
        if (joint.kind == ChainJointKind::kPrismatic) {
          v = a;
          w = {};
        } else if (joint.kind == ChainJointKind::kScrew) {
          v = v + a * joint.pitch;
        }
        const double vv[3] = {v.x, v.y, v.z}, ww[3] = {w.x, w.y, w.z};
        const int c = column + (ball ? k : 0);
        int rr = row;
        for (int d = 0; d < 3; ++d)
          if (bits & (kX << d)) (*out)(rr++, c) += scale * vv[d];
        for (int d = 0; d < 3; ++d)
          if (bits & (kAlpha << d)) (*out)(rr++, c) += scale * ww[d];
      }
    }
  };
  Jacobian J_point(3, n);

  for (int iteration = 0;; ++iteration) {
    // Errors and Jacobian rows, element by element.
    J.setZero();
    int r = 0;
    double worst_p = 0, worst_o = 0;
    for (const Element& e : elements_) {
      chain_values(e.chain, e.columns);
      const Pose X_WTip = e.chain.CalcTipPose(q_chain, ball_chain, X_WJ);
      Pose X_WTarget = e.X_WTarget;
      if (e.closed) {
        chain_values(e.target_chain, e.target_columns);
        X_WTarget = e.target_chain.CalcTipPose(q_chain, ball_chain, X_WJt);
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
      // Columns: revolute a x (p_tip - p_joint) and a; prismatic a and 0;
      // screw a x (p_tip - p_joint) + pitch a and a; spherical: the same
      // as revolute about each axis of its frame.
      add_columns(e.chain, e.columns, X_WJ, X_WTip.p, q_TW, e.constraints, r, 1.0, &J);
      // Closed chain: the target's joints move the target, so they enter
      // with the opposite sign (the error is target - tip).
      if (e.closed)
        add_columns(e.target_chain, e.target_columns, X_WJt, X_WTarget.p, q_TW, e.constraints, r,
                    -1.0, &J);
      for (int k = 0; k < 3; ++k)
        if (e.constraints & (kX << k)) err(r++) = ep[k];
      for (int k = 0; k < 3; ++k)
        if (e.constraints & (kAlpha << k)) err(r++) = eo[k];
    }
    // Avoidance rows, while a link's estimated distance is below its clearance.
    bool clear = true;
    for (size_t a = 0; a < avoid_.size(); ++a) {
      const AvoidLink& link = avoid_[a];
      if (!link.reading.near) continue;
      chain_values(link.chain, link.columns);
      const Pose X_WLink = link.chain.CalcTipPose(q_chain, ball_chain, X_WJ);
      const Vec3 p = X_WLink * p_L[a];
      const Vec3& nrm = link.reading.n_W;
      const double estimate = link.reading.distance + nrm.Dot(p - link.reading.p_WL);
      if (estimate >= link.clearance) continue;
      clear &= estimate >= link.clearance - settings.position_tolerance;
      // n^T dp/dq: the x, y, z rows of the point, projected on n.
      J_point.setZero();
      add_columns(link.chain, link.columns, X_WJ, p, Quat{}, kPosition, 0, 1.0, &J_point);
      J.row(r) = nrm.x * J_point.row(0) + nrm.y * J_point.row(1) + nrm.z * J_point.row(2);
      err(r++) = link.clearance - estimate;
    }
    result.iterations = iteration;
    result.position_error = worst_p;
    result.orientation_error = worst_o;
    if (worst_p <= settings.position_tolerance && worst_o <= settings.orientation_tolerance &&
        clear) {
      result.solved = true;
      break;
    }
    if (avoid_.empty()) {
      const double cost = err.head(r).squaredNorm();
      if (iteration > 0 && !(cost <= last_cost)) {  // (NaN too)
        // The last step made it worse: back to where it started, to step
        // again from there (its errors and Jacobian) damped more.
        q = q_last;
        ball = ball_last;
        result = last_result;
        result.iterations = iteration;
        J = J_last;
        err = err_last;
        r = r_last;
        lambda2 = std::max(lambda2 * kDampingGrowth, 1e-6);  // (from damping 0 too)
        if (iteration >= settings.max_iterations || !std::isfinite(lambda2)) break;
      } else {
        if (iteration > 0) lambda2 = std::max(lambda2_min, lambda2 / kDampingGrowth);
        last_cost = cost;
        q_last = q;
        ball_last = ball;
        last_result = result;
        J_last = J;
        err_last = err;
        r_last = r;
      }
    }
    if (iteration >= settings.max_iterations) break;
    // Damped least squares step, weighted (frozen and dependent columns:
    // 0), clamped.
    ColVector weights(n);
    for (int c = 0; c < n; ++c) weights(c) = frozen_[c] || master_[c] >= 0 ? 0.0 : weights_[c];
    const Jacobian Jr = J.topRows(r);  // the target rows and the active avoidance rows
    const RowVector er = err.head(r);
    ColVector dq;
    // A joint at a limit that the step would push past it sits this step
    // out, and the others' step is solved again without it (else the clamp
    // throws its share away and the others' share alone may not help: an
    // arm stopped short of a reachable target with one joint at a limit).
    for (int pass = 0; pass <= n; ++pass) {
      const Jacobian JW = Jr * weights.asDiagonal();
      Square A = JW * Jr.transpose();
      A.diagonal().array() += lambda2;
      const RowVector y = A.ldlt().solve(er);
      dq = JW.transpose() * y;
      bool dropped = false;
      for (int c = 0; c < n; ++c)
        if (kind_[c] == kOne && weights(c) != 0 &&
            ((q[c] >= max_[c] && dq(c) > 0) || (q[c] <= min_[c] && dq(c) < 0))) {
          weights(c) = 0;
          dropped = true;
        }
      if (!dropped) break;
    }
    // The step scaled as a whole to at most max_step in any joint: clamping
    // each joint on its own turns the step off its direction, which near
    // the stretched pose made most steps fail and the damping climb (a
    // reachable target took 25 iterations, past the default 20).
    double largest = 0;
    for (int c = 0; c < n; ++c)
      if (weights(c) != 0) largest = std::max(largest, std::abs(dq(c)));
    if (largest > settings.max_step) dq *= settings.max_step / largest;
    for (int c = 0; c < n; ++c) {
      if (weights(c) == 0 && kind_[c] == kOne) continue;  // keeps its value (and limits)
      if (kind_[c] == kBallX) {
        if (weights(c) == 0) continue;  // frozen
        const Vec3 step{std::clamp(dq(c), -settings.max_step, settings.max_step),
                        std::clamp(dq(c + 1), -settings.max_step, settings.max_step),
                        std::clamp(dq(c + 2), -settings.max_step, settings.max_step)};
        ball[c] = (FromRotationVector(step) * ball[c]).Normalized();
        continue;
      }
      if (kind_[c] != kOne) continue;
      const double step = std::clamp(dq(c), -settings.max_step, settings.max_step);
      q[c] = std::clamp(q[c] + step, min_[c], max_[c]);
    }
    for (int c = 0; c < n; ++c)
      if (master_[c] >= 0) q[c] = offset_[c] + factor_[c] * q[master_[c]];
  }
  if (result.solved || !settings.apply_only_when_solved) {
    *q_io = q;
    if (ball_io != nullptr) *ball_io = ball;
  }
  return result;
}

}  // namespace swarmsim::kinematics
