// PlanarWorld: build from the scene, the kinematic step and the Jacobi
// overlap resolution (planar_backend.h: the model and why).
#include "modules/dynamics/planar/planar_world.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "framework/error.h"
#include "framework/prefault.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "modules/dynamics/environment_obstacles.h"
#include "modules/dynamics/height_range.h"
#include "modules/dynamics/plane_wheels.h"
#include "modules/dynamics/scene_walk.h"

namespace swarmsim::planar {

namespace {

using dynamics::CalcHeightRange;
using dynamics::HeightRange;
using dynamics::PathAt;
using dynamics::ShapeAt;
using dynamics::ThrowIfNotFinite;

// Bodies per task of a parallel pass.
constexpr int64_t kGrain = 128;
// A shape whose z axis is this close to vertical is "upright".
constexpr double kUprightTolerance = 1e-6;

bool IsUpright(const Pose& X_WS) {
  return std::abs(X_WS.q.Rotate({0, 0, 1}).z) > 1 - kUprightTolerance;
}

// A largest value over threads, independent of their order (non-negative
// doubles compare like their bit patterns).
void AtomicMax(std::atomic<uint64_t>* max, double value) {
  const uint64_t bits = std::bit_cast<uint64_t>(value);
  uint64_t seen = max->load(std::memory_order_relaxed);
  while (bits > seen && !max->compare_exchange_weak(seen, bits, std::memory_order_relaxed)) {
  }
}

// The axis-aligned rectangle around points (x, y).
PlaneShape BoundingRectangle(double lo_x, double lo_y, double hi_x, double hi_y) {
  PlaneShape rect;
  rect.box = true;
  rect.x = 0.5 * (lo_x + hi_x);
  rect.y = 0.5 * (lo_y + hi_y);
  rect.hx = 0.5 * (hi_x - lo_x);
  rect.hy = 0.5 * (hi_y - lo_y);
  return rect;
}

// Bounding radius of a shape about its centre, m.
double BoundOf(const PlaneShape& shape) {
  return shape.box ? std::hypot(shape.hx, shape.hy) : shape.hx;
}

// A 3x3 symmetric matrix's inverse (cofactors), row-major.
void Invert3(const double m[9], double out[9]) {
  const double c00 = m[4] * m[8] - m[5] * m[7], c01 = m[5] * m[6] - m[3] * m[8],
               c02 = m[3] * m[7] - m[4] * m[6];
  const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
  const double k = 1.0 / det;
  out[0] = c00 * k;
  out[1] = (m[2] * m[7] - m[1] * m[8]) * k;
  out[2] = (m[1] * m[5] - m[2] * m[4]) * k;
  out[3] = c01 * k;
  out[4] = (m[0] * m[8] - m[2] * m[6]) * k;
  out[5] = (m[2] * m[3] - m[0] * m[5]) * k;
  out[6] = c02 * k;
  out[7] = (m[1] * m[6] - m[0] * m[7]) * k;
  out[8] = (m[0] * m[4] - m[1] * m[3]) * k;
}

}  // namespace

PlanarWorld::PlanarWorld(const Options& options, const DynamicsSettings& settings)
    : options_(options), settings_(settings) {
  if (options_.iterations < 1 || !(options_.tolerance >= 0) || !(options_.max_move_fraction > 0))
    throw Error("planar: iterations >= 1, tolerance >= 0 and max_move_fraction > 0 are needed");
}

template <class F>
void PlanarWorld::ForBodies(F&& body) {
  const int64_t n = static_cast<int64_t>(shapes_.size());
  if (settings_.scheduler == nullptr) {
    body(int64_t{0}, n);
    return;
  }
  settings_.scheduler->ParallelFor(0, n, kGrain, body);
}

void PlanarWorld::Build(const Scene& scene) {
  // 1. A body per dynamic shape, in slot order: circle or rectangle. The
  // bodies are counted first, and every per-body array is reserved at that
  // size with its pages populated on every thread: a million bodies' arrays
  // are fresh memory, which the kernel zeroed page by page on this thread as
  // they filled (most of this build's time on a VM whose memory was cold).
  size_t bodies = 0;
  for (const ShapeData& shape : scene.shapes()) bodies += shape.dynamic ? 1 : 0;
  const size_t joint_count = scene.rows(ObjectType::kJoint)->size();
  Prefault prefault;
  const auto reserve = [&](auto& v, size_t n) {
    v.clear();
    prefault.Reserve(v, n);
  };
  for (auto* v : {&shapes_, &next_}) reserve(*v, bodies);
  for (auto* v : {&bound_, &inner_, &inverse_mass_, &v_x_, &v_y_, &w_, &start_x_, &start_y_,
                  &start_yaw_, &ref_x_, &ref_y_})
    reserve(*v, bodies);
  for (auto* v : {&near_, &near_obstacles_}) reserve(*v, bodies);
  reserve(cold_, bodies);
  reserve(wheeled_, bodies);
  reserve(wheels_, joint_count);
  obstacles_.clear();
  shape_obstacles_ = 0;
  obstacle_poses_.Clear();
  std::vector<int32_t> body_of;
  reserve(body_of, scene.slot_count());
  if (settings_.scheduler != nullptr) prefault.Run(*settings_.scheduler);
  body_of.assign(scene.slot_count(), -1);
  HeightRange dynamic_range{std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity()};
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    const ShapeData* shape = ShapeAt(scene, s);
    if (!shape || !shape->dynamic) continue;
    const Pose& X_WS = scene.world_pose_at(s);
    ThrowIfNotFinite("planar", scene, s, X_WS);
    PlaneShape body;
    if (shape->kind == ShapeKind::kBox) {
      body.box = true;
      body.hx = 0.5 * shape->size.x;
      body.hy = 0.5 * shape->size.y;
    } else if (shape->kind == ShapeKind::kMesh && shape->mesh) {  // its bounding rectangle
      body.box = true;
      body.hx = 0.5 * (shape->mesh->hi().x - shape->mesh->lo().x);
      body.hy = 0.5 * (shape->mesh->hi().y - shape->mesh->lo().y);
    } else {
      body.hx = shape->size.x;
    }
    if (!(body.hx > 0) || (body.box && !(body.hy > 0)) || !std::isfinite(BoundOf(body)))
      throw Error("planar: dynamic shape '" + PathAt(scene, s) +
                  "' needs a positive size seen from above (size x " +
                  std::to_string(shape->size.x) + " m)");
    const double yaw = X_WS.q.Yaw();
    body.x = X_WS.p.x;
    body.y = X_WS.p.y;
    body.c = std::cos(yaw);
    body.s = std::sin(yaw);
    const HeightRange range = CalcHeightRange(*shape, X_WS);
    dynamic_range = {std::min(dynamic_range.lo, range.lo), std::max(dynamic_range.hi, range.hi)};
    body_of[s] = static_cast<int32_t>(shapes_.size());
    shapes_.push_back(body);
    bound_.push_back(BoundOf(body));
    inner_.push_back(body.box ? std::min(body.hx, body.hy) : body.hx);
    // Massless or unset: weighs like any other such body.
    inverse_mass_.push_back(shape->mass > 0 && std::isfinite(shape->mass) ? 1 / shape->mass : 1.0);
    PlanarBodyCold cold;
    cold.slot = s;
    cold.yaw = cold.yaw_last = yaw;
    cold.z = X_WS.p.z;
    cold.q_tilt = (Quat::FromYaw(-yaw) * X_WS.q).Normalized();
    cold.X_WB_last = X_WS;
    cold_.push_back(cold);
  }
  const size_t n = shapes_.size();
  next_ = shapes_;
  v_x_.assign(n, 0);
  v_y_.assign(n, 0);
  w_.assign(n, 0);
  start_x_.assign(n, 0);
  start_y_.assign(n, 0);
  start_yaw_.assign(n, 0);
  // 2. Obstacles: static shapes that are no part of a body and reach into the
  // bodies' height range, and the environment map's voxels there.
  dynamic_range_ = dynamic_range;
  if (n > 0) {
    // (Out of the height range too: they may move into it.)
    for (uint32_t s = 0; s < scene.slot_count(); ++s) {
      const ShapeData* shape = ShapeAt(scene, s);
      if (!shape || shape->dynamic || dynamics::NearestBodyAbove(scene, body_of, s, -1) >= 0)
        continue;
      if (shape->HasMovingSurface()) continue;  // a belt: no obstacle (as in box2d)
      obstacle_poses_.Add(s, scene.world_pose_at(s));
    }
    PlaceShapeObstacles(scene);
    ShapeData voxels;
    voxels.kind = ShapeKind::kBox;
    for (const EnvironmentBox& box : dynamics::EnvironmentObstacles(scene, dynamic_range, true)) {
      voxels.size = box.hi - box.lo;
      AddObstacle(voxels, {(box.lo + box.hi) * 0.5, {}});
    }
  }
  // 3. Wheels, grouped by body; each body's least-squares rolling solve.
  std::vector<std::pair<uint32_t, dynamics::PlaneWheelGeometry>> found;
  std::vector<uint32_t> joint_of;
  found.reserve(joint_count);
  joint_of.reserve(joint_count);
  dynamics::ForEachPlaneWheel(
      scene, body_of, [&](uint32_t b) { return cold_[b].slot; },
      [&](uint32_t joint_slot, const JointData& /*joint*/, uint32_t body,
          const dynamics::PlaneWheelGeometry& geometry) {
        found.push_back({body, geometry});
        joint_of.push_back(joint_slot);
      });
  std::vector<uint32_t> order(found.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return found[a].first < found[b].first; });
  for (size_t k = 0; k < order.size();) {
    const uint32_t body = found[order[k]].first;
    size_t end = k;
    while (end < order.size() && found[order[end]].first == body) ++end;
    // Rows: forward (= surface speed) and sideways (= 0) velocity of each
    // wheel's contact point, as functions of (vx, vy, w).
    double normal[9] = {};
    const auto add_row = [&](const double r[3]) {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) normal[3 * i + j] += r[i] * r[j];
    };
    for (size_t q = k; q < end; ++q) {
      const dynamics::PlaneWheelGeometry& g = found[order[q]].second;
      const double forward[3] = {g.f_x, g.f_y, g.f_y * g.p_x - g.f_x * g.p_y};
      const double side[3] = {-g.f_y, g.f_x, g.f_y * g.p_y + g.f_x * g.p_x};
      add_row(forward);
      add_row(side);
    }
    // A little regularisation: a single wheel (rank 2) gets the least-norm
    // motion instead of a singular matrix.
    const double trace = normal[0] + normal[4] + normal[8];
    const double det = normal[0] * (normal[4] * normal[8] - normal[5] * normal[7]) -
                       normal[1] * (normal[3] * normal[8] - normal[5] * normal[6]) +
                       normal[2] * (normal[3] * normal[7] - normal[4] * normal[6]);
    if (std::abs(det) <= 1e-9 * trace * trace * trace)
      for (int i = 0; i < 3; ++i) normal[4 * i] += 1e-9 * trace;
    double inverse[9];
    Invert3(normal, inverse);
    cold_[body].first_wheel = static_cast<uint32_t>(wheels_.size());
    cold_[body].wheel_count = static_cast<uint32_t>(end - k);
    for (size_t q = k; q < end; ++q) {
      const dynamics::PlaneWheelGeometry& g = found[order[q]].second;
      const double forward[3] = {g.f_x, g.f_y, g.f_y * g.p_x - g.f_x * g.p_y};
      PlanarWheel wheel;
      wheel.joint_slot = joint_of[order[q]];
      wheel.radius = g.radius;
      double* out[3] = {&wheel.g_vx, &wheel.g_vy, &wheel.g_w};
      for (int i = 0; i < 3; ++i)
        *out[i] = inverse[3 * i] * forward[0] + inverse[3 * i + 1] * forward[1] +
                  inverse[3 * i + 2] * forward[2];
      wheels_.push_back(wheel);
    }
    wheeled_.push_back(body);
    k = end;
  }
  // 4. Verlet skin: the mean bounding radius; the obstacles' grid.
  double sum = 0;
  for (double b : bound_) sum += b;
  skin_ = n > 0 ? sum / static_cast<double>(n) : 0;
  ref_x_.assign(n, 0);
  ref_y_.assign(n, 0);
  near_.assign(n, {});
  near_obstacles_.assign(n, {});
  IndexObstacles();
  max_speed_ratio_ = 0;
}

void PlanarWorld::PlaceShapeObstacles(const Scene& scene) {
  for (uint32_t s : obstacle_poses_.slots()) {
    const ShapeData& shape = scene.shapes()[scene.row_at(s)];
    const Pose& X_WS = scene.world_pose_at(s);
    ThrowIfNotFinite("planar", scene, s, X_WS);
    if (!dynamics::ReachesInto(CalcHeightRange(shape, X_WS), dynamic_range_)) continue;
    AddObstacle(shape, X_WS);
  }
  shape_obstacles_ = obstacles_.size();
}

void PlanarWorld::IndexObstacles() {
  items_.clear();
  for (uint32_t k = 0; k < obstacles_.size(); ++k)
    items_.push_back({obstacles_[k].x, obstacles_[k].y, BoundOf(obstacles_[k]) + 0.5 * skin_, k});
  obstacle_grid_.Build(items_);
  pairs_valid_ = false;
}

void PlanarWorld::AddObstacle(const ShapeData& shape, const Pose& X_WS) {
  const bool round = shape.kind == ShapeKind::kSphere ||
                     ((shape.kind == ShapeKind::kCylinder || shape.kind == ShapeKind::kCapsule) &&
                      IsUpright(X_WS));
  PlaneShape obstacle;
  if (round) {
    if (!(shape.size.x > 0)) return;
    obstacle.x = X_WS.p.x;
    obstacle.y = X_WS.p.y;
    obstacle.hx = shape.size.x;
  } else if (shape.kind == ShapeKind::kBox && IsUpright(X_WS)) {
    if (!(shape.size.x >= 0 && shape.size.y >= 0)) return;
    const double yaw = X_WS.q.Yaw();
    obstacle.box = true;
    obstacle.x = X_WS.p.x;
    obstacle.y = X_WS.p.y;
    obstacle.c = std::cos(yaw);
    obstacle.s = std::sin(yaw);
    obstacle.hx = 0.5 * shape.size.x;
    obstacle.hy = 0.5 * shape.size.y;
  } else {
    // A mesh, a tilted box or a lying cylinder: the axis-aligned rectangle
    // around its projection (conservative).
    std::vector<Vec3> points;
    if (shape.kind == ShapeKind::kMesh) {
      if (!shape.mesh) return;
      for (const Vec3& v : shape.mesh->vertices()) points.push_back(X_WS * v);
    } else {
      const Vec3 size = shape.kind == ShapeKind::kBox
                            ? shape.size
                            : Vec3{2 * shape.size.x, 2 * shape.size.x, shape.size.z};
      for (int i = 0; i < 8; ++i)
        points.push_back(X_WS * Vec3{(i & 1 ? 0.5 : -0.5) * size.x, (i & 2 ? 0.5 : -0.5) * size.y,
                                     (i & 4 ? 0.5 : -0.5) * size.z});
    }
    if (points.empty()) return;
    double lo_x = points[0].x, lo_y = points[0].y, hi_x = lo_x, hi_y = lo_y;
    for (const Vec3& p : points) {
      lo_x = std::min(lo_x, p.x);
      lo_y = std::min(lo_y, p.y);
      hi_x = std::max(hi_x, p.x);
      hi_y = std::max(hi_y, p.y);
    }
    obstacle = BoundingRectangle(lo_x, lo_y, hi_x, hi_y);
  }
  if (!std::isfinite(BoundOf(obstacle)) || !std::isfinite(obstacle.x) || !std::isfinite(obstacle.y))
    return;
  obstacles_.push_back(obstacle);
}

void PlanarWorld::SyncFromScene(const Scene& scene) {
  // A static shape that a script, a path or a joint moved: the obstacles
  // where they are now (the map's voxels stay), the bodies as they are.
  if (obstacle_poses_.Moved(scene)) {
    const std::vector<PlaneShape> voxels(obstacles_.begin() + shape_obstacles_, obstacles_.end());
    obstacles_.clear();
    PlaceShapeObstacles(scene);
    obstacles_.insert(obstacles_.end(), voxels.begin(), voxels.end());
    obstacle_poses_.Refresh(scene);
    IndexObstacles();
  }
  for (size_t b = 0; b < shapes_.size(); ++b) {
    PlanarBodyCold& cold = cold_[b];
    const Pose& X_WB = scene.world_pose_at(cold.slot);
    if (X_WB == cold.X_WB_last) continue;
    const double yaw = X_WB.q.Yaw();
    shapes_[b].x = X_WB.p.x;
    shapes_[b].y = X_WB.p.y;
    shapes_[b].c = std::cos(yaw);
    shapes_[b].s = std::sin(yaw);
    cold.yaw = cold.yaw_last = yaw;
    cold.z = X_WB.p.z;
    cold.q_tilt = (Quat::FromYaw(-yaw) * X_WB.q).Normalized();
    cold.X_WB_last = X_WB;
    pairs_valid_ = false;
  }
}

void PlanarWorld::ReadCommands(const Scene& scene, double duration) {
  max_speed_ratio_ = 0;
  const auto joints = scene.joints();
  for (uint32_t b : wheeled_) {
    const PlanarBodyCold& cold = cold_[b];
    double vx = 0, vy = 0, w = 0;
    for (uint32_t k = cold.first_wheel; k < cold.first_wheel + cold.wheel_count; ++k) {
      const PlanarWheel& wheel = wheels_[k];
      const JointData& joint = joints[scene.row_at(wheel.joint_slot)];
      const double speed =
          (joint.mode() == JointMode::kVelocity ? joint.DriveVelocity() : 0.0) * wheel.radius;
      vx += wheel.g_vx * speed;
      vy += wheel.g_vy * speed;
      w += wheel.g_w * speed;
    }
    if (!std::isfinite(vx) || !std::isfinite(vy) || !std::isfinite(w))
      throw Error("planar: body '" + PathAt(scene, cold.slot) + "' has a non-finite wheel command");
    v_x_[b] = vx;
    v_y_[b] = vy;
    w_[b] = w;
    const double speed = std::hypot(vx, vy) + std::abs(w) * bound_[b];
    max_speed_ratio_ = std::max(max_speed_ratio_, speed / (options_.max_move_fraction * inner_[b]));
  }
  // Velocities set from outside, in the body's frame, on top of its wheels'.
  // A body turning at w moves along an arc (Advance): the world velocity is
  // turned to the arc's chord, half the turn on (and lengthened by
  // (t/2) / sin(t/2)), so that it ends at p + v duration.
  for (const PushedBody& p : pushes_) {
    const uint32_t b = p.body;
    const PlaneShape& shape = shapes_[b];
    const bool wheeled = cold_[b].wheel_count > 0;
    const double half = 0.5 * p.w * duration;
    const double stretch = half != 0 ? half / std::sin(half) : 1.0;
    const double c = std::cos(half), s = std::sin(half);
    const double vx = stretch * (c * p.vx + s * p.vy), vy = stretch * (-s * p.vx + c * p.vy);
    v_x_[b] = (wheeled ? v_x_[b] : 0) + shape.c * vx + shape.s * vy;
    v_y_[b] = (wheeled ? v_y_[b] : 0) - shape.s * vx + shape.c * vy;
    w_[b] = (wheeled ? w_[b] : 0) + p.w;
    const double speed = std::hypot(v_x_[b], v_y_[b]) + std::abs(w_[b]) * bound_[b];
    max_speed_ratio_ = std::max(max_speed_ratio_, speed / (options_.max_move_fraction * inner_[b]));
  }
  // Faster than the internal steps can follow (Advance): it would cross
  // walls unseen. Said, naming the fastest body, instead.
  if (duration > 0 && std::ceil(duration * max_speed_ratio_) > options_.max_internal_steps) {
    uint32_t fastest = 0;
    double best = -1, best_speed = 0;
    for (uint32_t b = 0; b < shapes_.size(); ++b) {
      const double speed = std::hypot(v_x_[b], v_y_[b]) + std::abs(w_[b]) * bound_[b];
      if (const double ratio = speed / (options_.max_move_fraction * inner_[b]); ratio > best)
        best = ratio, best_speed = speed, fastest = b;
    }
    char text[320];
    std::snprintf(text, sizeof text,
                  "moves at %g m/s, %g times its inner radius (%g m) in one step of %g s: "
                  "planar cuts a step into at most %d internal steps of a quarter radius each, "
                  "so it would cross walls unseen; lower its speed or the time_step",
                  best_speed, best_speed * duration / inner_[fastest], inner_[fastest], duration,
                  options_.max_internal_steps);
    throw Error("planar: body '" + PathAt(scene, cold_[fastest].slot) + "' " + text);
  }
}

void PlanarWorld::Push(const Scene& scene, std::span<const uint32_t> slots) {
  std::vector<uint8_t> listed(scene.slot_count(), 0);
  for (const uint32_t slot : slots) listed[slot] = 1;
  pushes_.clear();
  for (uint32_t b = 0; b < cold_.size(); ++b) {
    const uint32_t slot = cold_[b].slot;
    if (listed[slot] == 0) continue;
    const Vec3& v = scene.linear_velocity_at(slot);
    pushes_.push_back({b, v.x, v.y, scene.angular_velocity_at(slot).z});
  }
}

void PlanarWorld::EndPushes() {
  for (const PushedBody& p : pushes_)
    if (cold_[p.body].wheel_count == 0) v_x_[p.body] = v_y_[p.body] = w_[p.body] = 0;
  pushes_.clear();
}

void PlanarWorld::RebuildPairs() {
  const size_t n = shapes_.size();
  items_.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    items_[i] = {shapes_[i].x, shapes_[i].y, bound_[i] + 0.5 * skin_, i};
    ref_x_[i] = shapes_[i].x;
    ref_y_[i] = shapes_[i].y;
  }
  body_grid_.Build(items_);
  ForBodies([&](int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      const double r = bound_[i] + 0.5 * skin_;
      body_grid_.QueryCircle(shapes_[i].x, shapes_[i].y, r, &near_[i]);
      std::erase(near_[i], static_cast<uint32_t>(i));
      if (obstacles_.empty())
        near_obstacles_[i].clear();
      else
        obstacle_grid_.QueryCircle(shapes_[i].x, shapes_[i].y, r, &near_obstacles_[i]);
    }
  });
  pairs_valid_ = true;
}

void PlanarWorld::Advance(double duration) {
  const size_t n = shapes_.size();
  for (size_t b = 0; b < n; ++b) {
    start_x_[b] = shapes_[b].x;
    start_y_[b] = shapes_[b].y;
    start_yaw_[b] = cold_[b].yaw;
  }
  // Internal steps: no body moves more than max_move_fraction of its inner
  // radius in one, so nothing crosses a wall or another body unseen.
  const double wanted = std::ceil(duration * max_speed_ratio_);
  const int steps =
      static_cast<int>(std::clamp(wanted, 1.0, static_cast<double>(options_.max_internal_steps)));
  last_internal_steps_ = steps;
  const double h = duration / steps;
  const double half_skin2 = 0.25 * skin_ * skin_;
  for (int step = 0; step < steps; ++step) {
    // 1. Rolling: each wheeled body along its arc.
    std::atomic<uint64_t> moved{0};  // largest squared distance from the Verlet reference
    ForBodies([&](int64_t begin, int64_t end) {
      double local = 0;
      for (int64_t b = begin; b < end; ++b) {
        PlaneShape& shape = shapes_[b];
        const double vx = v_x_[b], vy = v_y_[b], w = w_[b];
        if (vx != 0 || vy != 0 || w != 0) {
          double lx, ly;
          if (w == 0) {
            lx = vx * h;
            ly = vy * h;
          } else {
            const double turn = w * h, sn = std::sin(turn), one_minus_cos = 1 - std::cos(turn);
            lx = (sn * vx - one_minus_cos * vy) / w;
            ly = (one_minus_cos * vx + sn * vy) / w;
          }
          shape.x += shape.c * lx - shape.s * ly;
          shape.y += shape.s * lx + shape.c * ly;
          if (w != 0) {
            double& yaw = cold_[b].yaw;
            yaw += w * h;
            shape.c = std::cos(yaw);
            shape.s = std::sin(yaw);
          }
        }
        const double dx = shape.x - ref_x_[b], dy = shape.y - ref_y_[b];
        local = std::max(local, dx * dx + dy * dy);
      }
      AtomicMax(&moved, local);
    });
    if (!pairs_valid_ || std::bit_cast<double>(moved.load()) > half_skin2) RebuildPairs();
    // 2. Jacobi passes: each body reads the previous iterate only.
    for (int pass = 0; pass < options_.iterations; ++pass) {
      std::atomic<uint64_t> worst{0};  // deepest overlap between bodies seen in this pass
      ForBodies([&](int64_t begin, int64_t end) {
        double local = 0;
        for (int64_t i = begin; i < end; ++i) {
          const PlaneShape& a = shapes_[i];
          PlaneShape& out = next_[i];
          out = a;
          // Each overlap with another body split by mass (equal robots: half
          // each); the sum averaged past two contacts, so that a crowd does
          // not overshoot.
          double dx = 0, dy = 0;
          int count = 0;
          for (uint32_t j : near_[i]) {
            const PlaneShape& b = shapes_[j];
            PlaneContact contact = CalcContact(a, b);
            if (contact.depth <= 0) continue;
            if (a.x == b.x && a.y == b.y && static_cast<uint32_t>(i) > j) {
              contact.n_x = -contact.n_x;  // coincident centres: the two go apart
              contact.n_y = -contact.n_y;
            }
            const double share = inverse_mass_[i] / (inverse_mass_[i] + inverse_mass_[j]);
            dx += share * contact.depth * contact.n_x;
            dy += share * contact.depth * contact.n_y;
            local = std::max(local, contact.depth);
            ++count;
          }
          if (count > 2) {
            dx *= 2.0 / count;
            dy *= 2.0 / count;
          }
          out.x += dx;
          out.y += dy;
          // All of each overlap with an obstacle, twice over (corners).
          for (int sweep = 0; sweep < 2 && !near_obstacles_[i].empty(); ++sweep)
            for (uint32_t k : near_obstacles_[i]) {
              const PlaneContact contact = CalcContact(out, obstacles_[k]);
              if (contact.depth <= 0) continue;
              out.x += contact.depth * contact.n_x;
              out.y += contact.depth * contact.n_y;
            }
        }
        AtomicMax(&worst, local);
      });
      shapes_.swap(next_);
      if (std::bit_cast<double>(worst.load()) <= options_.tolerance) break;
    }
  }
}

void PlanarWorld::WriteBack(Scene* scene, double duration) {
  const double inverse = duration > 0 ? 1.0 / duration : 0.0;
  ForBodies([&](int64_t begin, int64_t end) {
    for (int64_t b = begin; b < end; ++b) {
      PlanarBodyCold& cold = cold_[b];
      const PlaneShape& shape = shapes_[b];
      Pose X_WB;
      X_WB.p = {shape.x, shape.y, cold.z};
      X_WB.q = cold.yaw == cold.yaw_last ? cold.X_WB_last.q : Quat::FromYaw(cold.yaw) * cold.q_tilt;
      scene->SetSimulatedState(
          cold.slot, X_WB,
          {(shape.x - start_x_[b]) * inverse, (shape.y - start_y_[b]) * inverse, 0},
          {0, 0, (cold.yaw - start_yaw_[b]) * inverse});
      cold.X_WB_last = X_WB;
      cold.yaw_last = cold.yaw;
    }
  });
}

void PlanarWorld::Hash(StateHasher* hasher) const {
  for (size_t b = 0; b < shapes_.size(); ++b) {
    hasher->AddValue(shapes_[b].x);
    hasher->AddValue(shapes_[b].y);
    hasher->AddValue(cold_[b].yaw);
  }
}

}  // namespace swarmsim::planar
