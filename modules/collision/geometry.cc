#include "modules/collision/geometry.h"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "framework/environment.h"
#include "framework/error.h"
#include "framework/mesh.h"
#include "framework/scene.h"

namespace swarmsim::collision {

namespace {

using Object = fcl::CollisionObjectd;
using GeometryPtr = std::shared_ptr<fcl::CollisionGeometryd>;

fcl::Transform3d ToFcl(const Pose& X) {
  fcl::Transform3d T = fcl::Transform3d::Identity();
  T.translation() = fcl::Vector3d(X.p.x, X.p.y, X.p.z);
  T.linear() = fcl::Quaterniond(X.q.w, X.q.x, X.q.y, X.q.z).toRotationMatrix();
  return T;
}

Vec3 FromFcl(const fcl::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

uint32_t SlotOf(const Object* o) {
  return static_cast<uint32_t>(reinterpret_cast<uintptr_t>(o->getUserData()));
}

// Distance between two objects, 0 when they touch; closest points (world).
double PairDistance(const Object* a, const Object* b, Vec3* pa, Vec3* pb) {
  fcl::DistanceRequestd request(true);
  request.gjk_solver_type = fcl::GST_INDEP;
  request.distance_tolerance = 1e-9;
  fcl::DistanceResultd result;
  fcl::distance(a, b, request, result);
  if (result.min_distance > 0) {
    *pa = FromFcl(result.nearest_points[0]);
    *pb = FromFcl(result.nearest_points[1]);
    return result.min_distance;
  }
  // Touching or overlapping: a contact point stands for both.
  fcl::CollisionRequestd c(1, true);
  c.gjk_solver_type = fcl::GST_INDEP;
  fcl::CollisionResultd r;
  if (fcl::collide(a, b, c, r) > 0) {
    *pa = *pb = FromFcl(r.getContact(0).pos);
  } else {
    *pa = FromFcl(result.nearest_points[0]);
    *pb = FromFcl(result.nearest_points[1]);
  }
  return 0;
}

// Is `slot` in the ascending list `slots`?
bool Contains(std::span<const uint32_t> slots, uint32_t slot) {
  return std::binary_search(slots.begin(), slots.end(), slot);
}

struct DistanceQuery {
  const Object* query = nullptr;
  uint32_t query_slot = kNoSlot;
  std::span<const uint32_t> exclude;  // ascending
  DistanceAnswer* best = nullptr;
  double bound = 0;  // the best so far, or the threshold
};

void Offer(DistanceQuery* q, const Object* other, uint32_t other_slot) {
  Vec3 pa, pb;
  const double d = PairDistance(q->query, other, &pa, &pb);
  if (d <= q->bound && (!q->best->found || d < q->best->distance)) {
    *q->best = {true, d, pa, pb, q->query_slot, other_slot};
    q->bound = d;
  }
}

bool TreeDistance(Object* o1, Object* o2, void* data, double& dist) {
  auto* q = static_cast<DistanceQuery*>(data);
  const Object* other = o1 == q->query ? o2 : o1;
  const uint32_t slot = SlotOf(other);
  if (slot == kMapSlot || !Contains(q->exclude, slot)) Offer(q, other, slot);
  dist = q->bound;
  return q->bound <= 0;
}

struct CollideQuery {
  const Object* query = nullptr;
  uint32_t query_slot = kNoSlot;
  std::span<const uint32_t> exclude;
  int max_contacts = 0;
  CollisionAnswer* answer = nullptr;
};

// True when the pair collides; contacts appended up to the limit.
bool PairCollide(CollideQuery* q, const Object* other, uint32_t other_slot) {
  fcl::CollisionRequestd request(static_cast<size_t>(std::max(q->max_contacts, 1)),
                                 q->max_contacts > 0);
  request.gjk_solver_type = fcl::GST_INDEP;
  fcl::CollisionResultd result;
  if (fcl::collide(q->query, other, request, result) == 0) return false;
  CollisionAnswer& a = *q->answer;
  if (!a.colliding) a = {true, q->query_slot, other_slot, {}};
  for (size_t i = 0;
       i < result.numContacts() && a.contacts.size() < static_cast<size_t>(q->max_contacts); ++i)
    a.contacts.push_back(FromFcl(result.getContact(i).pos));
  return true;
}

bool TreeCollide(Object* o1, Object* o2, void* data) {
  auto* q = static_cast<CollideQuery*>(data);
  const Object* other = o1 == q->query ? o2 : o1;
  const uint32_t slot = SlotOf(other);
  if (slot != kMapSlot && Contains(q->exclude, slot)) return false;
  PairCollide(q, other, slot);
  // Without contacts asked for, the first colliding pair settles it.
  return q->answer->colliding && q->answer->contacts.size() >= static_cast<size_t>(q->max_contacts);
}

}  // namespace

struct Geometry::Impl {
  uint64_t version = UINT64_MAX;
  const EnvironmentMap* map = nullptr;
  std::vector<std::unique_ptr<Object>> objects;  // by slot; null: not a shape
  std::vector<uint32_t> moving;                  // slots of shapes that may move
  std::vector<uint32_t> fixed;                   // slots of static shapes (ascending)
  std::vector<std::unique_ptr<Object>> map_boxes;
  // Shared geometry: one BVH per mesh asset (the asset kept alive with it),
  // one primitive per kind and size.
  std::map<const TriangleMesh*, std::pair<std::shared_ptr<const TriangleMesh>, GeometryPtr>> meshes;
  std::map<std::tuple<int, double, double, double>, GeometryPtr> primitives;
  fcl::DynamicAABBTreeCollisionManagerd fixed_tree, moving_tree;

  GeometryPtr Primitive(ShapeKind kind, const Vec3& size) {
    GeometryPtr& g = primitives[{static_cast<int>(kind), size.x, size.y, size.z}];
    if (g) return g;
    switch (kind) {
      case ShapeKind::kBox: g = std::make_shared<fcl::Boxd>(size.x, size.y, size.z); break;
      case ShapeKind::kSphere: g = std::make_shared<fcl::Sphered>(size.x); break;
      case ShapeKind::kCylinder: g = std::make_shared<fcl::Cylinderd>(size.x, size.z); break;
      case ShapeKind::kCapsule:
        g = std::make_shared<fcl::Capsuled>(size.x, std::max(0.0, size.z - 2 * size.x));
        break;
      case ShapeKind::kMesh: break;
    }
    return g;
  }

  GeometryPtr Mesh(const std::shared_ptr<const TriangleMesh>& mesh) {
    auto& entry = meshes[mesh.get()];
    if (entry.second) return entry.second;
    auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
    std::vector<fcl::Vector3d> points;
    points.reserve(mesh->vertices().size());
    for (const Vec3& v : mesh->vertices()) points.emplace_back(v.x, v.y, v.z);
    std::vector<fcl::Triangle> triangles;
    triangles.reserve(mesh->triangles().size());
    for (const MeshTriangle& t : mesh->triangles()) triangles.emplace_back(t.v[0], t.v[1], t.v[2]);
    model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(points.size()));
    model->addSubModel(points, triangles);
    model->endModel();
    model->computeLocalAABB();
    entry = {mesh, model};
    return model;
  }

  void Rebuild(const Scene& scene) {
    std::vector<uint32_t> fixed_now;
    objects.clear();
    objects.resize(scene.slot_count());
    moving.clear();
    const auto shapes = scene.shapes();
    const auto owners = scene.shape_owners();
    for (size_t r = 0; r < shapes.size(); ++r) {
      const uint32_t slot = owners[r];
      if (!scene.alive_at(slot)) continue;
      const ShapeData& s = shapes[r];
      GeometryPtr g = s.kind == ShapeKind::kMesh ? (s.mesh ? Mesh(s.mesh) : nullptr)
                                                 : Primitive(s.kind, s.size);
      if (!g) continue;
      auto o = std::make_unique<Object>(g, ToFcl(scene.world_pose_at(slot)));
      o->setUserData(reinterpret_cast<void*>(static_cast<uintptr_t>(slot)));
      o->computeAABB();
      objects[slot] = std::move(o);
      (scene.instance_of_at(slot) < 0 && !s.dynamic ? fixed_now : moving).push_back(slot);
    }
    std::sort(fixed_now.begin(), fixed_now.end());
    std::sort(moving.begin(), moving.end());
    // The environment tree only when its contents changed (the map's boxes
    // are many; robots come and go without touching it).
    if (fixed_now != fixed || map != scene.environment() || version == UINT64_MAX) {
      fixed = std::move(fixed_now);
      map = scene.environment();
      map_boxes.clear();
      if (map != nullptr) {
        map_boxes.reserve(map->boxes.size());
        for (const EnvironmentBox& b : map->boxes) {
          const Vec3 size = b.hi - b.lo;
          auto o = std::make_unique<Object>(Primitive(ShapeKind::kBox, size),
                                            ToFcl({(b.lo + b.hi) * 0.5, {}}));
          o->setUserData(reinterpret_cast<void*>(static_cast<uintptr_t>(kMapSlot)));
          o->computeAABB();
          map_boxes.push_back(std::move(o));
        }
      }
    }
    std::vector<Object*> list;
    for (uint32_t slot : fixed) list.push_back(objects[slot].get());
    for (auto& o : map_boxes) list.push_back(o.get());
    fixed_tree.clear();
    fixed_tree.registerObjects(list);
    fixed_tree.setup();
    list.clear();
    for (uint32_t slot : moving) list.push_back(objects[slot].get());
    moving_tree.clear();
    moving_tree.registerObjects(list);
    moving_tree.setup();
    version = scene.structure_version();
  }
};

Geometry::Geometry() : impl_(std::make_unique<Impl>()) {}
Geometry::~Geometry() = default;

size_t Geometry::object_count() const {
  return impl_->moving.size() + impl_->fixed.size() + impl_->map_boxes.size();
}

void Geometry::Refresh(const Scene& scene) {
  Impl& m = *impl_;
  if (m.version != scene.structure_version() || m.map != scene.environment()) {
    m.Rebuild(scene);
    return;
  }
  for (uint32_t slot : m.moving) {
    m.objects[slot]->setTransform(ToFcl(scene.world_pose_at(slot)));
    m.objects[slot]->computeAABB();
  }
  m.moving_tree.update();
}

std::vector<uint32_t> Geometry::ShapesOf(const Scene& scene,
                                         std::span<const uint32_t> slots) const {
  std::vector<uint32_t> out;
  for (uint32_t s : slots)
    if (s < impl_->objects.size() && impl_->objects[s] && scene.alive_at(s)) out.push_back(s);
  return out;
}

DistanceAnswer Geometry::Distance(std::span<const uint32_t> a, const Target& b, double threshold,
                                  uint32_t hint_a, uint32_t hint_b) const {
  const Impl& m = *impl_;
  DistanceAnswer best;
  DistanceQuery q;
  q.best = &best;
  q.bound = threshold;
  q.exclude = a;
  // Temporal coherence: last step's closest pair first; its distance now
  // bounds every other pair (most are culled on their bounding boxes).
  if (hint_a != kNoSlot && hint_b != kNoSlot && hint_b != kMapSlot && Contains(a, hint_a) &&
      hint_a < m.objects.size() && hint_b < m.objects.size() && m.objects[hint_a] &&
      m.objects[hint_b]) {
    const bool allowed = b.kind == EntitySpec::kPath ? Contains(b.slots, hint_b)
                         : b.kind == EntitySpec::kEnvironment
                             ? std::binary_search(m.fixed.begin(), m.fixed.end(), hint_b)
                             : !Contains(a, hint_b);
    if (allowed) {
      q.query = m.objects[hint_a].get();
      q.query_slot = hint_a;
      Offer(&q, m.objects[hint_b].get(), hint_b);
    }
  }
  for (uint32_t sa : a) {
    const Object* oa = m.objects[sa].get();
    q.query = oa;
    q.query_slot = sa;
    switch (b.kind) {
      case EntitySpec::kPath:
        for (uint32_t sb : b.slots) {
          if (sb == sa || Contains(a, sb)) continue;
          const Object* ob = m.objects[sb].get();
          if (oa->getAABB().distance(ob->getAABB()) > q.bound) continue;
          Offer(&q, ob, sb);
        }
        break;
      case EntitySpec::kEverythingElse:
        m.moving_tree.distance(const_cast<Object*>(oa), &q, TreeDistance);
        [[fallthrough]];
      case EntitySpec::kEnvironment:
        m.fixed_tree.distance(const_cast<Object*>(oa), &q, TreeDistance);
        break;
    }
    if (best.found && best.distance <= 0) break;
  }
  return best;
}

CollisionAnswer Geometry::Collide(std::span<const uint32_t> a, const Target& b,
                                  int max_contacts) const {
  const Impl& m = *impl_;
  CollisionAnswer answer;
  CollideQuery q;
  q.answer = &answer;
  q.exclude = a;
  q.max_contacts = max_contacts;
  const auto done = [&] {
    return answer.colliding && answer.contacts.size() >= static_cast<size_t>(max_contacts);
  };
  for (uint32_t sa : a) {
    const Object* oa = m.objects[sa].get();
    q.query = oa;
    q.query_slot = sa;
    switch (b.kind) {
      case EntitySpec::kPath:
        for (uint32_t sb : b.slots) {
          if (sb == sa || Contains(a, sb)) continue;
          const Object* ob = m.objects[sb].get();
          if (!oa->getAABB().overlap(ob->getAABB())) continue;
          PairCollide(&q, ob, sb);
          if (done()) break;
        }
        break;
      case EntitySpec::kEverythingElse:
        m.moving_tree.collide(const_cast<Object*>(oa), &q, TreeCollide);
        if (done()) break;
        [[fallthrough]];
      case EntitySpec::kEnvironment:
        m.fixed_tree.collide(const_cast<Object*>(oa), &q, TreeCollide);
        break;
    }
    if (done()) break;
  }
  return answer;
}

}  // namespace swarmsim::collision
