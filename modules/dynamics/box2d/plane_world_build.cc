// PlaneWorld::Build and its phases: the scene projected to the plane as
// bodies, ground fixtures, wheels and ground friction (see box2d_backend.h for
// what becomes what).
#include <box2d/b2_body.h>
#include <box2d/b2_circle_shape.h>
#include <box2d/b2_fixture.h>
#include <box2d/b2_friction_joint.h>
#include <box2d/b2_polygon_shape.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "modules/dynamics/box2d/plane_world.h"
#include "modules/dynamics/environment_obstacles.h"
#include "modules/dynamics/plane_wheels.h"
#include "modules/dynamics/scene_walk.h"

namespace swarmsim::box2d {

namespace {

using dynamics::CalcHeightRange;
using dynamics::PathAt;
using dynamics::ShapeAt;
using dynamics::ThrowIfNotFinite;

// A shape whose z axis is this close to vertical is "upright".
constexpr double kUprightTolerance = 1e-6;
// Restitution applies above this approach speed, m/s (Box2D's default is
// 1 unit/s, i.e. 0.1 m/s at the default scale; keep that whatever the scale).
constexpr double kRestitutionThreshold = 0.1;
bool IsUpright(const Pose& X_WS) {
  return std::abs(X_WS.q.Rotate({0, 0, 1}).z) > 1 - kUprightTolerance;
}

// Area-preserving footprint radius of a shape, m.
double FootprintRadius(const ShapeData& shape) {
  if (shape.kind == ShapeKind::kBox) return std::sqrt(shape.size.x * shape.size.y / M_PI);
  if (shape.kind == ShapeKind::kMesh && shape.mesh) {  // of its bounding box
    const Vec3 e = shape.mesh->hi() - shape.mesh->lo();
    return std::sqrt(e.x * e.y / M_PI);
  }
  return shape.size.x;
}

// Moment of inertia about the vertical axis through the centre, kg m^2.
double CalcInertia(const ShapeData& shape) {
  const double m = shape.mass;
  switch (shape.kind) {
    case ShapeKind::kBox:
      return m * (shape.size.x * shape.size.x + shape.size.y * shape.size.y) / 12;
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
      return 0.5 * m * shape.size.x * shape.size.x;  // capsule: as its cylinder
    case ShapeKind::kSphere: return 0.4 * m * shape.size.x * shape.size.x;
    case ShapeKind::kMesh: {  // its bounding box's, about the shape's origin
      const Vec3 lo = shape.mesh ? shape.mesh->lo() : shape.size * -0.5;
      const Vec3 hi = shape.mesh ? shape.mesh->hi() : shape.size * 0.5;
      const Vec3 e = hi - lo, c = (lo + hi) * 0.5;
      return m * (e.x * e.x + e.y * e.y) / 12 + m * (c.x * c.x + c.y * c.y);
    }
  }
  return 0;
}

// A rectangle of half extents (hx, hy) units, shrunk by the polygon skin so
// that the collision surface is the real face (when the box is big enough).
void SetSkinnedBox(double hx, double hy, const b2Vec2& center, double angle, b2PolygonShape* out) {
  const double r = b2_polygonRadius;
  if (hx > 2 * r && hy > 2 * r) {
    hx -= r;
    hy -= r;
  }
  out->SetAsBox(static_cast<float>(hx), static_cast<float>(hy), center, static_cast<float>(angle));
}

// A point in the plane, Box2D units.
struct PlanePoint {
  double x, y;
};

// The convex hull of `points` as convex polygons of at most
// b2_maxPolygonVertices (a fan cut of the hull: exact, not simplified), with
// the vertices Box2D would weld dropped first, so that b2PolygonShape::Set
// never sees a collapsed hull (it asserts). No skin correction: the
// collision surface is the hull grown by b2_polygonRadius. False when the
// hull has no area.
bool HullPolygons(std::vector<PlanePoint> points, std::vector<b2PolygonShape>* out) {
  using P = PlanePoint;
  std::sort(points.begin(), points.end(),
            [](const P& a, const P& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  // Andrew's monotone chain, counter-clockwise, collinear points dropped.
  auto cross = [](const P& o, const P& a, const P& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  std::vector<P> hull(2 * points.size() + 1);
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k > 0 ? k - 1 : 0);
  // Drop vertices Box2D would weld (closer than a linear slop).
  const double weld = b2_linearSlop;
  std::vector<b2Vec2> kept;
  for (const P& p : hull) {
    if (!kept.empty() && std::hypot(p.x - kept.back().x, p.y - kept.back().y) < weld) continue;
    kept.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
  }
  while (kept.size() > 1 && b2Distance(kept.front(), kept.back()) < weld) kept.pop_back();
  if (kept.size() < 3) return false;
  double area = 0;
  for (size_t i = 0; i < kept.size(); ++i) area += b2Cross(kept[i], kept[(i + 1) % kept.size()]);
  if (area * 0.5 < 4 * b2_linearSlop * b2_linearSlop) return false;
  // Fan pieces: vertex 0 with up to 7 consecutive others.
  const size_t n = kept.size();
  for (size_t j = 1; j + 1 < n; j += b2_maxPolygonVertices - 2) {
    b2Vec2 piece[b2_maxPolygonVertices];
    int count = 0;
    piece[count++] = kept[0];
    for (size_t i = j; i < n && count < b2_maxPolygonVertices; ++i) piece[count++] = kept[i];
    out->emplace_back();
    out->back().Set(piece, count);
  }
  return true;
}

// A mesh in the plane: the hull of its vertices projected by X (mesh frame
// -> plane frame, metres), L units per metre (HullPolygons).
bool MeshPolygons(const TriangleMesh& mesh, const Pose& X, double L,
                  std::vector<b2PolygonShape>* out) {
  std::vector<PlanePoint> points;
  points.reserve(mesh.vertices().size());
  for (const Vec3& v : mesh.vertices()) {
    const Vec3 p = X * v;
    points.push_back({p.x * L, p.y * L});
  }
  return HullPolygons(std::move(points), out);
}

// The fixtures of a dynamic shape's body, in its plane frame, L units per
// metre. The fixture's density gives the body the shape's mass (Box2D
// ignores the polygon skin in its mass); the caller then sets the inertia to
// the real shape's.
void AddBodyFixtures(const Scene& scene, uint32_t slot, const ShapeData& shape, const Pose& X_WS,
                     double L, b2Body* body) {
  b2FixtureDef fixture;
  fixture.friction = static_cast<float>(shape.friction);
  fixture.restitution = static_cast<float>(shape.restitution);
  fixture.restitutionThreshold = static_cast<float>(kRestitutionThreshold * L);
  b2CircleShape circle;
  b2PolygonShape polygon;
  std::vector<b2PolygonShape> pieces;  // a mesh's hull
  if (shape.kind == ShapeKind::kMesh) {
    // In the body's plane frame: the shape's tilt applied, its yaw not.
    const Pose X_PS{{}, (Quat::FromYaw(-X_WS.q.Yaw()) * X_WS.q).Normalized()};
    if (!shape.mesh || !MeshPolygons(*shape.mesh, X_PS, L, &pieces))
      throw Error("box2d: dynamic mesh '" + PathAt(scene, slot) +
                  "' has no area seen from above (its hull in the plane is degenerate)");
    fixture.density = 1;  // the mass is set by the caller
    for (size_t i = 0; i + 1 < pieces.size(); ++i) {
      fixture.shape = &pieces[i];
      body->CreateFixture(&fixture);
    }
    fixture.shape = &pieces.back();
  } else if (shape.kind == ShapeKind::kBox) {
    SetSkinnedBox(0.5 * shape.size.x * L, 0.5 * shape.size.y * L, b2Vec2(0, 0), 0, &polygon);
    b2MassData unit;
    polygon.ComputeMass(&unit, 1.0f);
    fixture.shape = &polygon;
    fixture.density = static_cast<float>(shape.mass / unit.mass);
  } else {
    circle.m_radius = static_cast<float>(shape.size.x * L);
    fixture.shape = &circle;
    fixture.density = static_cast<float>(shape.mass / (M_PI * circle.m_radius * circle.m_radius));
  }
  body->CreateFixture(&fixture);
}
}  // namespace

void PlaneWorld::Build(const Scene& scene) {
  // 0. A fresh world: its ground body holds the obstacles and friction joints.
  Reset();
  // 1. A body per dynamic shape, in slot order.
  std::vector<int32_t> body_of(scene.slot_count(), -1);  // body index of a dynamic shape (slots)
  const HeightRange dynamic_range = BuildBodies(scene, &body_of);
  dynamic_range_ = dynamic_range;
  // 2. Obstacles: non-dynamic shapes that are not parts of a body, projected
  // to the plane, as fixtures of the ground body.
  if (!bodies_.empty()) BuildObstacles(scene, body_of, dynamic_range);
  // 2b. Belts: moving surfaces that are no part of a body (plane_belts.cc).
  if (!bodies_.empty()) BuildBelts(scene, body_of);
  // 3. Wheels: velocity-mode revolute joints under a body, with a horizontal
  // axis and a round child, in slot order, then grouped by body.
  BuildWheels(scene, body_of);
  // 4. No wheels: Coulomb friction with the ground.
  BuildGroundFriction(scene);
  // 5. Force sensors.
  if (force_sensor::Any(scene)) BuildForceSensors(scene, body_of);
}

void PlaneWorld::Reset() {
  world_ = std::make_unique<b2World>(b2Vec2(0, 0));  // top-down: no gravity in the plane
  bodies_.clear();
  body_poses_.clear();
  wheeled_.clear();
  wheels_.clear();
  belts_.clear();
  riders_.clear();
  force_sensors_.clear();
  ghosts_.clear();
  obstacle_poses_.Clear();
  b2BodyDef ground_def;
  ground_ = world_->CreateBody(&ground_def);
}

HeightRange PlaneWorld::BuildBodies(const Scene& scene, std::vector<int32_t>* body_of) {
  HeightRange dynamic_range{std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity()};
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    const ShapeData* shape = ShapeAt(scene, s);
    if (!shape || !shape->dynamic) continue;
    const Pose& X_WS = scene.world_pose_at(s);
    ThrowIfNotFinite("box2d", scene, s, X_WS);
    const bool box = shape->kind == ShapeKind::kBox;
    if (!(shape->mass > 0) || !(shape->size.x > 0) || (box && !(shape->size.y > 0)) ||
        !std::isfinite(shape->mass))
      throw Error("box2d: dynamic shape '" + PathAt(scene, s) +
                  "' needs a positive mass and size (mass " + std::to_string(shape->mass) +
                  " kg, size x " + std::to_string(shape->size.x) + " m)");
    const HeightRange range = CalcHeightRange(*shape, X_WS);
    dynamic_range = {std::min(dynamic_range.lo, range.lo), std::max(dynamic_range.hi, range.hi)};
    (*body_of)[s] = static_cast<int32_t>(bodies_.size());
    AddBody(scene, s, *shape, X_WS);
  }
  return dynamic_range;
}

void PlaneWorld::AddBody(const Scene& scene, uint32_t slot, const ShapeData& shape,
                         const Pose& X_WS) {
  const double L = scale_;
  const double yaw = X_WS.q.Yaw();
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position.Set(static_cast<float>(X_WS.p.x * L), static_cast<float>(X_WS.p.y * L));
  def.angle = static_cast<float>(yaw);
  const Vec3& v_WS = scene.linear_velocity_at(slot);
  def.linearVelocity.Set(static_cast<float>(v_WS.x * L), static_cast<float>(v_WS.y * L));
  def.angularVelocity = static_cast<float>(scene.angular_velocity_at(slot).z);
  b2Body* body = world_->CreateBody(&def);
  AddBodyFixtures(scene, slot, shape, X_WS, L, body);
  b2MassData mass;
  mass.mass = static_cast<float>(shape.mass);
  mass.center.SetZero();
  mass.I = static_cast<float>(CalcInertia(shape) * L * L);
  body->SetMassData(&mass);

  PlaneBody plane_body;
  plane_body.body = body;
  plane_body.slot = slot;
  plane_body.inverse_mass = body->GetMass() > 0 ? 1.0 / body->GetMass() : 0.0;
  plane_body.inverse_inertia = body->GetInertia() > 0 ? 1.0 / body->GetInertia() : 0.0;
  bodies_.push_back(plane_body);
  PlaneBodyPose pose;
  pose.z = X_WS.p.z;
  pose.q_tilt = (Quat::FromYaw(-yaw) * X_WS.q).Normalized();
  pose.X_WB_last = X_WS;
  body_poses_.push_back(pose);
}

void PlaneWorld::BuildObstacles(const Scene& scene, const std::vector<int32_t>& body_of,
                                const HeightRange& dynamic_range) {
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    const ShapeData* shape = ShapeAt(scene, s);
    if (!shape || shape->dynamic || dynamics::NearestBodyAbove(scene, body_of, s, -1) >= 0)
      continue;
    // A moving surface (a belt) carries bodies: no obstacle (BuildBelts).
    if (shape->HasMovingSurface()) continue;
    obstacle_poses_.Add(
        s, scene.world_pose_at(s));  // out of the height range too: it may move into it
  }
  AddShapeObstacles(scene, obstacle_poses_.slots(), dynamic_range);
  // The environment map's voxels in that range, projected and merged into
  // rectangles (fixtures of the ground body like the shapes above).
  ShapeData voxels;  // the default material
  for (const EnvironmentBox& box : dynamics::EnvironmentObstacles(scene, dynamic_range, true)) {
    voxels.kind = ShapeKind::kBox;
    voxels.size = box.hi - box.lo;
    AddObstacle(voxels, {(box.lo + box.hi) * 0.5, {}});
  }
}

void PlaneWorld::AddShapeObstacles(const Scene& scene, std::span<const uint32_t> slots,
                                   const HeightRange& dynamic_range) {
  for (uint32_t s : slots) {
    const ShapeData& shape = scene.shapes()[scene.row_at(s)];
    const Pose& X_WS = scene.world_pose_at(s);
    ThrowIfNotFinite("box2d", scene, s, X_WS);
    if (!dynamics::ReachesInto(CalcHeightRange(shape, X_WS), dynamic_range)) continue;
    AddObstacle(shape, X_WS, uintptr_t{s} + 1);
  }
}

void PlaneWorld::RemoveShapeObstacles(std::span<const uint32_t> slots) {
  std::vector<b2Fixture*> doomed;
  for (b2Fixture* f = ground_->GetFixtureList(); f; f = f->GetNext()) {
    const uintptr_t tag = f->GetUserData().pointer;
    if (tag != 0 && std::binary_search(slots.begin(), slots.end(), static_cast<uint32_t>(tag - 1)))
      doomed.push_back(f);
  }
  for (b2Fixture* f : doomed) ground_->DestroyFixture(f);
}

void PlaneWorld::AddObstacle(const ShapeData& shape, const Pose& X_WS, uintptr_t tag) {
  const double L = scale_;
  b2FixtureDef fixture;
  fixture.userData.pointer = tag;
  fixture.friction = static_cast<float>(shape.friction);
  fixture.restitution = static_cast<float>(shape.restitution);
  fixture.restitutionThreshold = static_cast<float>(kRestitutionThreshold * L);
  const b2Vec2 center(static_cast<float>(X_WS.p.x * L), static_cast<float>(X_WS.p.y * L));
  b2CircleShape circle;
  b2PolygonShape polygon;
  const bool round = shape.kind == ShapeKind::kSphere ||
                     ((shape.kind == ShapeKind::kCylinder || shape.kind == ShapeKind::kCapsule) &&
                      IsUpright(X_WS));
  // A mesh, or a tilted box or lying cylinder: the hull of the points
  // projected to the plane, in pieces (none: no area seen from above).
  std::vector<b2PolygonShape> pieces;
  const auto add_pieces = [&] {
    for (const b2PolygonShape& piece : pieces) {
      fixture.shape = &piece;
      ground_->CreateFixture(&fixture);
    }
  };
  if (shape.kind == ShapeKind::kMesh) {
    if (shape.mesh && MeshPolygons(*shape.mesh, X_WS, L, &pieces)) add_pieces();
    return;
  }
  if (round) {
    if (!(shape.size.x > 0)) return;
    circle.m_p = center;
    circle.m_radius = static_cast<float>(shape.size.x * L);
    fixture.shape = &circle;
  } else {
    // Box extents; a lying cylinder is taken as its bounding box.
    const Vec3 size = shape.kind == ShapeKind::kBox
                          ? shape.size
                          : Vec3{2 * shape.size.x, 2 * shape.size.x, shape.size.z};
    if (!(size.x > 0 && size.y > 0 && size.z >= 0)) return;
    if (IsUpright(X_WS)) {
      SetSkinnedBox(0.5 * size.x * L, 0.5 * size.y * L, center, X_WS.q.Yaw(), &polygon);
    } else {
      // Tilted: the hull of the eight projected corners (a vertical sheet
      // seen edge on has none and is skipped).
      std::vector<PlanePoint> corners;
      for (int i = 0; i < 8; ++i) {
        const Vec3 p_SC{(i & 1 ? 0.5 : -0.5) * size.x, (i & 2 ? 0.5 : -0.5) * size.y,
                        (i & 4 ? 0.5 : -0.5) * size.z};
        const Vec3 p_WC = X_WS * p_SC;
        corners.push_back({p_WC.x * L, p_WC.y * L});
      }
      if (HullPolygons(std::move(corners), &pieces)) add_pieces();
      return;
    }
    fixture.shape = &polygon;
  }
  ground_->CreateFixture(&fixture);
}

void PlaneWorld::BuildWheels(const Scene& scene, const std::vector<int32_t>& body_of) {
  dynamics::ForEachPlaneWheel(
      scene, body_of, [&](uint32_t b) { return bodies_[b].slot; },
      [&](uint32_t joint_slot, const JointData& joint, uint32_t body,
          const dynamics::PlaneWheelGeometry& geometry) {
        AddWheel(joint_slot, joint, body, geometry);
      });
  std::stable_sort(wheels_.begin(), wheels_.end(),
                   [](const PlaneWheel& a, const PlaneWheel& b) { return a.body < b.body; });
  for (uint32_t w = 0; w < wheels_.size(); ++w) {
    PlaneBody& body = bodies_[wheels_[w].body];
    if (body.wheel_count == 0) body.first_wheel = w;
    ++body.wheel_count;
  }
  // Each wheel carries an equal share of its body's weight.
  for (uint32_t b = 0; b < bodies_.size(); ++b) {
    const PlaneBody& body = bodies_[b];
    if (body.wheel_count == 0) continue;
    wheeled_.push_back(b);
    const ShapeData& shape = scene.shapes()[scene.row_at(body.slot)];
    const double load = shape.mass * settings_.gravity / body.wheel_count;
    for (uint32_t w = body.first_wheel; w < body.first_wheel + body.wheel_count; ++w)
      wheels_[w].coulomb_rate *= load * scale_;
  }
}

void PlaneWorld::AddWheel(uint32_t joint_slot, const JointData& joint, uint32_t body_index,
                          const dynamics::PlaneWheelGeometry& geometry) {
  const double L = scale_;
  const double radius = geometry.radius;
  const PlaneBody& body = bodies_[body_index];
  PlaneWheel wheel;
  wheel.body = body_index;
  wheel.joint_slot = joint_slot;
  wheel.p_x = geometry.p_x * L;
  wheel.p_y = geometry.p_y * L;
  wheel.f_x = geometry.f_x;
  wheel.f_y = geometry.f_y;
  wheel.radius_m = radius;
  wheel.coulomb_rate = geometry.shape->friction;  // times m g / n (BuildWheels)
  wheel.motor_rate = std::max(0.0, joint.settings->max_force) / radius * L;
  // Inverse effective mass at the contact point: K = [m^-1 + I^-1 py^2, -I^-1 px py;
  // -I^-1 px py, m^-1 + I^-1 px^2], inverted.
  const double im = body.inverse_mass, ii = body.inverse_inertia;
  const double k11 = im + ii * wheel.p_y * wheel.p_y, k22 = im + ii * wheel.p_x * wheel.p_x;
  const double k12 = -ii * wheel.p_x * wheel.p_y;
  const double det = k11 * k22 - k12 * k12;
  wheel.k_xx = k22 / det;
  wheel.k_xy = -k12 / det;
  wheel.k_yy = k11 / det;
  wheels_.push_back(wheel);
}

void PlaneWorld::BuildGroundFriction(const Scene& scene) {
  const double L = scale_;
  for (uint32_t b = 0; b < bodies_.size(); ++b) {
    const PlaneBody& body = bodies_[b];
    if (body.wheel_count > 0) continue;
    // A disc of uniform pressure resists turning with 2/3 mu m g r.
    const ShapeData& shape = scene.shapes()[scene.row_at(body.slot)];
    b2FrictionJointDef def;
    def.Initialize(ground_, body.body, body.body->GetWorldCenter());
    def.collideConnected = true;  // the obstacles are ground fixtures: still walls to it
    const double force = shape.friction * shape.mass * settings_.gravity;
    def.maxForce = static_cast<float>(force * L);
    def.maxTorque = static_cast<float>(2.0 / 3.0 * force * FootprintRadius(shape) * L * L);
    b2Joint* joint = world_->CreateJoint(&def);
    if (!belts_.empty())
      AddRider(scene, b, static_cast<b2FrictionJoint*>(joint), def.maxForce, def.maxTorque);
  }
}

}  // namespace swarmsim::box2d
