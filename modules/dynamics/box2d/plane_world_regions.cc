// PlaneWorld's part in a partitioned plane (plane_partition.h): copying
// ground fixtures, moving bodies between regions, and ghosts.
#include <box2d/b2_body.h>
#include <box2d/b2_circle_shape.h>
#include <box2d/b2_fixture.h>
#include <box2d/b2_friction_joint.h>
#include <box2d/b2_polygon_shape.h>
#include <box2d/b2_world.h>
#include <box2d/b2_world_callbacks.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "modules/dynamics/box2d/plane_world.h"

namespace swarmsim::box2d {

namespace {

// What makes another fixture like `f` (sharing its shape).
b2FixtureDef DefinitionOf(const b2Fixture* f) {
  b2FixtureDef def;
  def.shape = f->GetShape();
  def.friction = f->GetFriction();
  def.restitution = f->GetRestitution();
  def.restitutionThreshold = f->GetRestitutionThreshold();
  def.density = f->GetDensity();
  def.isSensor = f->IsSensor();
  def.filter = f->GetFilterData();
  def.userData = const_cast<b2Fixture*>(f)->GetUserData();  // (Box2D 2.4 has no const getter)
  return def;
}

// The fixtures of `from` added to `to`, in their creation order (Box2D keeps
// them newest first).
void CloneFixtures(const b2Body* from, b2Body* to) {
  std::vector<const b2Fixture*> fixtures;
  for (const b2Fixture* f = from->GetFixtureList(); f; f = f->GetNext()) fixtures.push_back(f);
  for (auto it = fixtures.rbegin(); it != fixtures.rend(); ++it) {
    const b2Fixture* f = *it;
    const b2FixtureDef def = DefinitionOf(f);
    to->CreateFixture(&def);
  }
}

}  // namespace

void PlaneWorld::CopyGround(const PlaneWorld& from, int axis, double lo, double hi, double cross_lo,
                            double cross_hi) {
  struct Wake final : b2QueryCallback {
    bool ReportFixture(b2Fixture* fixture) override {
      if (fixture->GetBody()->GetType() == b2_dynamicBody) fixture->GetBody()->SetAwake(true);
      return true;
    }
  } wake;
  std::vector<const b2Fixture*> fixtures;
  for (const b2Fixture* f = from.ground_->GetFixtureList(); f; f = f->GetNext())
    fixtures.push_back(f);
  for (auto it = fixtures.rbegin(); it != fixtures.rend(); ++it) {
    const b2Fixture* f = *it;
    // The exact AABB of each child of the shape (a chain has several).
    bool reaches = false;
    for (int c = 0; c < f->GetShape()->GetChildCount() && !reaches; ++c) {
      b2AABB box;
      f->GetShape()->ComputeAABB(&box, from.ground_->GetTransform(), c);
      const double a_lo = axis == 0 ? box.lowerBound.x : box.lowerBound.y;
      const double a_hi = axis == 0 ? box.upperBound.x : box.upperBound.y;
      const double c_lo = axis == 0 ? box.lowerBound.y : box.lowerBound.x;
      const double c_hi = axis == 0 ? box.upperBound.y : box.upperBound.x;
      reaches = a_hi >= lo && a_lo <= hi && c_hi >= cross_lo && c_lo <= cross_hi;
    }
    if (!reaches) continue;
    const b2FixtureDef def = DefinitionOf(f);
    const b2Fixture* copy = ground_->CreateFixture(&def);
    // Bodies asleep where it lands wake to meet it.
    for (int c = 0; c < copy->GetShape()->GetChildCount(); ++c)
      world_->QueryAABB(&wake, copy->GetAABB(c));
  }
}

void PlaneWorld::CopyBody(uint32_t b, PlaneWorld* to) const {
  const PlaneBody& plane_body = bodies_[b];
  b2Body* body = plane_body.body;
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position = body->GetPosition();
  def.angle = body->GetAngle();  // unwrapped, as it was
  def.linearVelocity = body->GetLinearVelocity();
  def.angularVelocity = body->GetAngularVelocity();
  def.awake = body->IsAwake();
  b2Body* moved = to->world_->CreateBody(&def);
  CloneFixtures(body, moved);
  b2MassData mass;
  body->GetMassData(&mass);
  moved->SetMassData(&mass);
  // Its ground friction (bodies without wheels), limits unchanged.
  for (const b2JointEdge* edge = body->GetJointList(); edge; edge = edge->next) {
    if (edge->joint->GetType() != e_frictionJoint) continue;
    const auto* friction = static_cast<const b2FrictionJoint*>(edge->joint);
    b2FrictionJointDef joint;
    joint.Initialize(to->ground_, moved, moved->GetWorldCenter());
    joint.collideConnected = true;
    joint.maxForce = friction->GetMaxForce();
    joint.maxTorque = friction->GetMaxTorque();
    to->world_->CreateJoint(&joint);
  }
  const uint32_t index = static_cast<uint32_t>(to->bodies_.size());
  PlaneBody copy = plane_body;
  copy.body = moved;
  copy.first_wheel = static_cast<uint32_t>(to->wheels_.size());
  for (uint32_t w = 0; w < plane_body.wheel_count; ++w) {
    PlaneWheel wheel = wheels_[plane_body.first_wheel + w];
    wheel.body = index;
    to->wheels_.push_back(wheel);
  }
  to->bodies_.push_back(copy);
  to->body_poses_.push_back(body_poses_[b]);
  if (copy.wheel_count > 0) to->wheeled_.push_back(index);
}

void PlaneWorld::MoveBody(uint32_t b, PlaneWorld* to) {
  CopyBody(b, to);
  world_->DestroyBody(bodies_[b].body);
  bodies_[b].body = nullptr;  // a hole until Compact()
}

void PlaneWorld::Compact() {
  std::vector<uint32_t> new_index(bodies_.size(), 0);
  std::vector<PlaneWheel> wheels;
  wheels.reserve(wheels_.size());
  size_t kept = 0;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    if (!bodies_[b].body) continue;
    new_index[b] = static_cast<uint32_t>(kept);
    PlaneBody body = bodies_[b];
    const uint32_t first = static_cast<uint32_t>(wheels.size());
    for (uint32_t w = 0; w < body.wheel_count; ++w) {
      PlaneWheel wheel = wheels_[body.first_wheel + w];
      wheel.body = static_cast<uint32_t>(kept);
      wheels.push_back(wheel);
    }
    body.first_wheel = first;
    bodies_[kept] = body;
    body_poses_[kept] = body_poses_[b];
    ++kept;
  }
  if (kept == bodies_.size()) return;
  bodies_.resize(kept);
  body_poses_.resize(kept);
  wheels_ = std::move(wheels);
  wheeled_.clear();
  for (uint32_t b = 0; b < bodies_.size(); ++b)
    if (bodies_[b].wheel_count > 0) wheeled_.push_back(b);
}

double PlaneWorld::SpeedBound(uint32_t b) const {
  const PlaneBody& plane_body = bodies_[b];
  double speed = plane_body.body->GetLinearVelocity().Length();
  for (uint32_t w = 0; w < plane_body.wheel_count; ++w) {
    const PlaneWheel& wheel = wheels_[plane_body.first_wheel + w];
    // A turning body's rim moves faster than its wheels: count the wheel's
    // distance from the centre too.
    const double reach = std::hypot(wheel.p_x, wheel.p_y);
    speed = std::max(speed, std::abs(wheel.surface_speed) * (1 + reach));
  }
  return speed;
}

double PlaneWorld::BoundingRadius(const b2Body* body) {
  double radius = 0;
  for (const b2Fixture* f = body->GetFixtureList(); f; f = f->GetNext()) {
    const b2Shape* shape = f->GetShape();
    if (shape->GetType() == b2Shape::e_circle) {
      const auto* circle = static_cast<const b2CircleShape*>(shape);
      radius = std::max(radius, static_cast<double>(circle->m_p.Length() + circle->m_radius));
    } else if (shape->GetType() == b2Shape::e_polygon) {
      const auto* polygon = static_cast<const b2PolygonShape*>(shape);
      for (int i = 0; i < polygon->m_count; ++i)
        radius = std::max(radius,
                          static_cast<double>(polygon->m_vertices[i].Length() + polygon->m_radius));
    }
  }
  return radius;
}

void PlaneWorld::SetGhosts(const std::vector<std::pair<uint32_t, const b2Body*>>& wanted) {
  std::vector<PlaneGhost> ghosts;
  ghosts.reserve(wanted.size());
  size_t old = 0;
  for (const auto& [slot, owner] : wanted) {
    while (old < ghosts_.size() && ghosts_[old].slot < slot)
      world_->DestroyBody(ghosts_[old++].body);
    if (old < ghosts_.size() && ghosts_[old].slot == slot) {
      ghosts.push_back(ghosts_[old++]);
      continue;
    }
    b2BodyDef def;
    def.type = b2_kinematicBody;
    def.position = owner->GetPosition();
    def.angle = owner->GetAngle();
    def.linearVelocity = owner->GetLinearVelocity();
    def.angularVelocity = owner->GetAngularVelocity();
    def.awake = owner->IsAwake();
    b2Body* ghost = world_->CreateBody(&def);
    CloneFixtures(owner, ghost);
    ghosts.push_back({slot, ghost});
  }
  while (old < ghosts_.size()) world_->DestroyBody(ghosts_[old++].body);
  ghosts_ = std::move(ghosts);
}

void PlaneWorld::RefreshGhosts(const PlaneBodyState* states, const uint32_t* state_of_slot) {
  for (const PlaneGhost& ghost : ghosts_) {
    const PlaneBodyState& state = states[state_of_slot[ghost.slot]];
    b2Body* body = ghost.body;
    const b2Vec2 p(state.x, state.y);
    if (body->GetPosition() != p || body->GetAngle() != state.angle)
      body->SetTransform(p, state.angle);
    body->SetLinearVelocity(b2Vec2(state.vx, state.vy));
    body->SetAngularVelocity(state.w);
    body->SetAwake(state.awake);
  }
}

void PlaneWorld::PublishStates(PlaneBodyState* states, const uint32_t* state_of_slot) const {
  for (const PlaneBody& plane_body : bodies_) {
    const b2Body* body = plane_body.body;
    PlaneBodyState& state = states[state_of_slot[plane_body.slot]];
    state.x = body->GetPosition().x;
    state.y = body->GetPosition().y;
    state.angle = body->GetAngle();
    state.vx = body->GetLinearVelocity().x;
    state.vy = body->GetLinearVelocity().y;
    state.w = body->GetAngularVelocity();
    state.awake = body->IsAwake();
  }
}

}  // namespace swarmsim::box2d
