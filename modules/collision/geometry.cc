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
#include "framework/spatial_grid.h"
#include "modules/collision/prisms.h"

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

// An object's key, its user data: a shape's slot, or kMapKeyBase + the
// index of a map box (a deterministic order for ties).
constexpr uint64_t kMapKeyBase = uint64_t{1} << 32;
uint64_t KeyOf(const Object* o) { return reinterpret_cast<uintptr_t>(o->getUserData()); }
uint32_t SlotOf(const Object* o) {
  const uint64_t key = KeyOf(o);
  return key < kMapKeyBase ? static_cast<uint32_t>(key) : kMapSlot;
}

// A query object whose bounding box is set directly: a range for gathering
// the objects of a tree whose boxes overlap it.
struct RangeBox : fcl::CollisionObjectd {
  explicit RangeBox(const GeometryPtr& g) : fcl::CollisionObjectd(g) {}
  void Set(const fcl::AABBd& box) { aabb = box; }
};

struct GatherData {
  const Object* range;
  std::vector<const Object*>* out;
};

bool Gather(Object* o1, Object* o2, void* data) {
  auto* g = static_cast<GatherData*>(data);
  g->out->push_back(o1 == g->range ? o2 : o1);
  return false;
}

struct Candidate {
  double lb;     // distance between the bounding boxes: no pair is closer
  uint32_t a;    // the first side's shape
  uint64_t key;  // the other object's key
  const Object* b;
};

// The prisms of the shapes (by slot) and of the map's boxes (by index).
Prism PrismOf(const ShapeData& s, const Pose& X) {
  switch (s.kind) {
    case ShapeKind::kBox: return BoxPrism(X, s.size);
    case ShapeKind::kCylinder: {
      const Prism p = CylinderPrism(X, s.size.x, s.size.z);
      return p.kind != Prism::kNone ? p : LyingCylinderBound(X, s.size.x, s.size.z);
    }
    default: return {};
  }
}

struct PrismTable {
  const std::vector<Prism>* shapes = nullptr;
  const std::vector<Prism>* map = nullptr;
  const Prism& Of(uint64_t key) const {
    return key < kMapKeyBase ? (*shapes)[key] : (*map)[key - kMapKeyBase];
  }
};

// Distance between two objects, 0 when they touch; closest points (world).
// Vertical prisms in closed form (prisms.h), the rest by FCL's GJK.
double PairDistance(const PrismTable& prisms, const Object* a, const Object* b, Vec3* pa,
                    Vec3* pb) {
  double d = 0;
  const Prism& prism_a = prisms.Of(KeyOf(a));
  const Prism& prism_b = prisms.Of(KeyOf(b));
  if (prism_a.exact && prism_b.exact && PrismDistance(prism_a, prism_b, &d, pa, pb)) return d;
  fcl::DistanceRequestd request(true);
  request.gjk_solver_type = fcl::GST_INDEP;
  request.distance_tolerance = 1e-6;
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

// No pair of points of a and b is closer: their bounding boxes' and
// bounding spheres' distances, and their prisms' when they have some.
double LowerBound(const PrismTable& prisms, const Object* a, const Object* b, double bound) {
  const fcl::CollisionGeometryd& ga = *a->collisionGeometry();
  const fcl::CollisionGeometryd& gb = *b->collisionGeometry();
  const double spheres =
      (a->getTransform() * ga.aabb_center - b->getTransform() * gb.aabb_center).norm() -
      ga.aabb_radius - gb.aabb_radius;
  const double cheap = std::max(a->getAABB().distance(b->getAABB()), spheres);
  if (cheap > bound) return cheap;  // culled anyway
  bound = cheap;
  // Prisms around both (a wheel's, a wall's): tighter still.
  double d = 0;
  Vec3 pa, pb;
  if (PrismDistance(prisms.Of(KeyOf(a)), prisms.Of(KeyOf(b)), &d, &pa, &pb))
    bound = std::max(bound, d);
  return bound;
}

struct DistanceQuery {
  PrismTable prisms;
  const Object* query = nullptr;
  uint32_t query_slot = kNoSlot;
  std::span<const uint32_t> exclude;  // ascending
  DistanceAnswer* best = nullptr;
  double bound = 0;  // the best so far, or the threshold
};

void Offer(DistanceQuery* q, const Object* other, uint32_t other_slot) {
  Vec3 pa, pb;
  const double d = PairDistance(q->prisms, q->query, other, &pa, &pb);
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
  uint64_t map_version = UINT64_MAX;             // Scene::environment_version of `map`
  std::vector<std::unique_ptr<Object>> objects;  // by slot; null: not a shape
  std::vector<uint32_t> moving;                  // slots of shapes that may move
  std::vector<uint32_t> fixed;                   // slots of static shapes (ascending)
  std::vector<Pose> fixed_poses;                 // their world poses in fixed_tree (fixed)
  std::vector<std::unique_ptr<Object>> map_boxes;
  std::vector<Prism> prisms;      // by slot (kNone: not a vertical prism)
  std::vector<Prism> map_prisms;  // by map box
  // Shared geometry: one BVH per mesh asset (the asset kept alive with it),
  // one primitive per kind and size.
  std::map<const TriangleMesh*, std::pair<std::shared_ptr<const TriangleMesh>, GeometryPtr>> meshes;
  std::map<std::tuple<int, double, double, double>, GeometryPtr> primitives;
  fcl::DynamicAABBTreeCollisionManagerd fixed_tree;
  // The moving shapes in a uniform grid of their bounding circles, rebuilt
  // each step (cheaper than refitting a tree, and queries are ascending).
  SpatialGrid moving_grid;
  std::vector<GridItem> moving_items;

  void IndexMoving() {
    moving_items.resize(moving.size());
    for (size_t i = 0; i < moving.size(); ++i) {
      const fcl::AABBd& b = objects[moving[i]]->getAABB();
      const double hx = (b.max_[0] - b.min_[0]) / 2, hy = (b.max_[1] - b.min_[1]) / 2;
      moving_items[i] = {b.min_[0] + hx, b.min_[1] + hy, std::sqrt(hx * hx + hy * hy),
                         static_cast<uint32_t>(i)};
    }
    moving_grid.Build(moving_items);
  }

  // Appends the moving objects whose bounding circles meet `box` (xy).
  void GatherMoving(const fcl::AABBd& box, std::vector<const Object*>* out) const {
    moving_grid.ForEachInAabb(
        {box.min_[0], box.min_[1], box.max_[0], box.max_[1]},
        [&](uint32_t i, const GridItem&) { out->push_back(objects[moving[i]].get()); });
  }
  GeometryPtr unit_box = std::make_shared<fcl::Boxd>(1, 1, 1);  // for range queries

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
    prisms.assign(scene.slot_count(), Prism{});
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
      prisms[slot] = PrismOf(s, scene.world_pose_at(slot));
      (scene.instance_of_at(slot) < 0 && !s.dynamic ? fixed_now : moving).push_back(slot);
    }
    std::sort(fixed_now.begin(), fixed_now.end());
    std::sort(moving.begin(), moving.end());
    // The environment tree only when its contents changed (the map's boxes
    // are many; robots come and go without touching it).
    if (fixed_now != fixed || map_version != scene.environment_version() || version == UINT64_MAX) {
      fixed = std::move(fixed_now);
      map = scene.environment();
      map_version = scene.environment_version();
      map_boxes.clear();
      map_prisms.clear();
      if (map != nullptr) {
        map_boxes.reserve(map->boxes.size());
        for (const EnvironmentBox& b : map->boxes) {
          const Vec3 size = b.hi - b.lo;
          auto o = std::make_unique<Object>(Primitive(ShapeKind::kBox, size),
                                            ToFcl({(b.lo + b.hi) * 0.5, {}}));
          o->setUserData(
              reinterpret_cast<void*>(static_cast<uintptr_t>(kMapKeyBase + map_boxes.size())));
          o->computeAABB();
          map_boxes.push_back(std::move(o));
          map_prisms.push_back(BoxPrism({(b.lo + b.hi) * 0.5, {}}, size));
        }
      }
    }
    std::vector<Object*> list;
    fixed_poses.clear();
    for (uint32_t slot : fixed) {
      list.push_back(objects[slot].get());
      fixed_poses.push_back(scene.world_pose_at(slot));
    }
    for (auto& o : map_boxes) list.push_back(o.get());
    fixed_tree.clear();
    fixed_tree.registerObjects(list);
    fixed_tree.setup();
    IndexMoving();
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
  if (m.version != scene.structure_version() || m.map_version != scene.environment_version()) {
    m.Rebuild(scene);
    return;
  }
  const auto shapes = scene.shapes();
  // Static shapes a script, a path or a joint moved: moved in the
  // environment tree too (few, and most never move).
  std::vector<Object*> moved;
  for (size_t i = 0; i < m.fixed.size(); ++i) {
    const uint32_t slot = m.fixed[i];
    const Pose& X = scene.world_pose_at(slot);
    if (X == m.fixed_poses[i]) continue;
    m.fixed_poses[i] = X;
    m.objects[slot]->setTransform(ToFcl(X));
    m.objects[slot]->computeAABB();
    m.prisms[slot] = PrismOf(shapes[scene.row_at(slot)], X);
    moved.push_back(m.objects[slot].get());
  }
  if (!moved.empty()) m.fixed_tree.update(moved);
  for (uint32_t slot : m.moving) {
    const Pose& X = scene.world_pose_at(slot);
    m.objects[slot]->setTransform(ToFcl(X));
    m.objects[slot]->computeAABB();
    m.prisms[slot] = PrismOf(shapes[scene.row_at(slot)], X);
  }
  m.IndexMoving();
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
  q.prisms = {&m.prisms, &m.map_prisms};
  q.best = &best;
  q.bound = threshold;
  q.exclude = a;
  // Temporal coherence: last step's closest pair first; its distance now
  // bounds the search, so that only pairs whose bounding boxes come closer
  // are measured.
  const bool hinted = hint_a != kNoSlot && hint_b < m.objects.size() && Contains(a, hint_a) &&
                      hint_a < m.objects.size() && m.objects[hint_a] && m.objects[hint_b];
  if (hinted) {
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
  // No bound yet (no threshold, no usable pair): FCL's own traversal for the
  // first shape finds one.
  if (!std::isfinite(q.bound) && b.kind != EntitySpec::kPath && !a.empty()) {
    q.query = m.objects[a[0]].get();
    q.query_slot = a[0];
    m.fixed_tree.distance(const_cast<Object*>(q.query), &q, TreeDistance);
  }
  // Every pair whose bounding boxes are within the bound, nearest boxes
  // first; stop at the first whose boxes are farther than the best so far.
  thread_local std::vector<Candidate> candidates;
  thread_local std::vector<const Object*> found;
  candidates.clear();
  found.clear();
  const auto offer = [&](uint32_t sa, const Object* ob) {
    const uint64_t key = KeyOf(ob);
    if (key < kMapKeyBase && Contains(a, static_cast<uint32_t>(key))) return;
    if (hinted && sa == hint_a && key == hint_b) return;  // measured already
    const double lb = LowerBound(q.prisms, m.objects[sa].get(), ob, q.bound);
    if (lb <= q.bound) candidates.push_back({lb, sa, key, ob});
  };
  // Measures the candidates gathered, nearest bounding boxes first, until
  // the next one's boxes are farther than the best so far.
  const auto measure = [&] {
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
      return std::tie(x.lb, x.a, x.key) < std::tie(y.lb, y.a, y.key);
    });
    for (const Candidate& c : candidates) {
      if (c.lb > q.bound) break;
      q.query = m.objects[c.a].get();
      q.query_slot = c.a;
      Offer(&q, c.b, c.key < kMapKeyBase ? static_cast<uint32_t>(c.key) : kMapSlot);
      if (best.found && best.distance <= 0) break;
    }
  };
  if (b.kind == EntitySpec::kPath) {
    for (uint32_t sa : a)
      for (uint32_t sb : b.slots) offer(sa, m.objects[sb].get());
    measure();
  } else if (!a.empty()) {
    // Range queries around the first side's shapes (their boxes grown by a
    // reach), the reach growing fourfold until the best distance found is
    // within it: nothing outside the grown box can be closer. Without it a
    // first query in a large swarm (no hint, the nearest wall far away)
    // would gather every robot's shapes (10,000 hexapods: 190,000 per robot).
    fcl::AABBd box = m.objects[a[0]]->getAABB();
    for (uint32_t sa : a) box += m.objects[sa]->getAABB();
    double reach = std::max({box.width(), box.height(), box.depth(), 0.25});
    fcl::AABBd previous;
    for (bool first = true;; first = false) {
      const double bound = std::isfinite(q.bound) ? q.bound : 1e18;
      const double grow = std::min(reach, bound);
      RangeBox range(m.unit_box);
      range.Set(fcl::AABBd(box.min_ - fcl::Vector3d::Constant(grow),
                           box.max_ + fcl::Vector3d::Constant(grow)));
      GatherData gather{&range, &found};
      found.clear();
      candidates.clear();
      if (b.kind == EntitySpec::kEverythingElse) m.GatherMoving(range.getAABB(), &found);
      m.fixed_tree.collide(&range, &gather, Gather);
      // Objects the last round's box reached were offered then (the bound
      // only shrinks, so what it culled stays culled).
      for (const Object* ob : found)
        if (first || !ob->getAABB().overlap(previous))
          for (uint32_t sa : a) offer(sa, ob);
      measure();
      if (grow >= bound || q.bound <= grow) break;
      previous = range.getAABB();
      reach *= 4;
    }
  }
  return best;
}

namespace {

// The shape `oa` (slot `sa`, one of `a`) against `b`; true when the query
// is settled (a collision found and enough contacts).
template <typename Impl>
bool CollideOne(const Impl& m, const Object* oa, uint32_t sa, std::span<const uint32_t> a,
                const Target& b, CollideQuery* q) {
  const auto done = [&] {
    return q->answer->colliding &&
           q->answer->contacts.size() >= static_cast<size_t>(q->max_contacts);
  };
  q->query = oa;
  q->query_slot = sa;
  switch (b.kind) {
    case EntitySpec::kPath:
      for (uint32_t sb : b.slots) {
        if (sb == sa || Contains(a, sb)) continue;
        const Object* ob = m.objects[sb].get();
        if (!oa->getAABB().overlap(ob->getAABB())) continue;
        PairCollide(q, ob, sb);
        if (done()) break;
      }
      break;
    case EntitySpec::kEverythingElse: {
      thread_local std::vector<const Object*> near;
      near.clear();
      m.GatherMoving(oa->getAABB(), &near);
      for (const Object* ob : near) {
        const uint32_t sb = SlotOf(ob);
        if (Contains(a, sb) || !oa->getAABB().overlap(ob->getAABB())) continue;
        PairCollide(q, ob, sb);
        if (done()) break;
      }
      if (done()) break;
      [[fallthrough]];
    }
    case EntitySpec::kEnvironment:
      m.fixed_tree.collide(const_cast<Object*>(oa), q, TreeCollide);
      break;
  }
  return done();
}

}  // namespace

CollisionAnswer Geometry::Collide(std::span<const uint32_t> a, const Target& b,
                                  int max_contacts) const {
  const Impl& m = *impl_;
  CollisionAnswer answer;
  CollideQuery q;
  q.answer = &answer;
  q.exclude = a;
  q.max_contacts = max_contacts;
  for (uint32_t sa : a)
    if (CollideOne(m, m.objects[sa].get(), sa, a, b, &q)) break;
  return answer;
}

struct Probe::Impl {
  const Geometry::Impl* geometry = nullptr;
  std::vector<uint32_t> slots;  // ascending
  std::vector<Pose> X_FS;       // each shape's pose in the frame
  std::vector<std::unique_ptr<Object>> objects;
};

Probe::Probe(const Geometry& geometry, const Scene& scene, std::span<const uint32_t> shapes,
             const Pose& X_WF)
    : impl_(std::make_unique<Impl>()) {
  Impl& p = *impl_;
  p.geometry = geometry.impl_.get();
  const Pose X_FW = X_WF.Inverse();
  for (uint32_t slot : shapes) {
    if (slot >= p.geometry->objects.size() || !p.geometry->objects[slot]) continue;
    p.slots.push_back(slot);
    p.X_FS.push_back(X_FW * scene.world_pose_at(slot));
    auto o = std::make_unique<Object>(std::const_pointer_cast<fcl::CollisionGeometryd>(
        p.geometry->objects[slot]->collisionGeometry()));
    o->setUserData(reinterpret_cast<void*>(static_cast<uintptr_t>(slot)));
    p.objects.push_back(std::move(o));
  }
}

Probe::~Probe() = default;

bool Probe::Collides(const Pose& X_WF, const Target& b) {
  Impl& p = *impl_;
  CollisionAnswer answer;
  CollideQuery q;
  q.answer = &answer;
  q.exclude = p.slots;
  for (size_t i = 0; i < p.objects.size(); ++i) {
    Object& o = *p.objects[i];
    o.setTransform(ToFcl(X_WF * p.X_FS[i]));
    o.computeAABB();
    if (CollideOne(*p.geometry, &o, p.slots[i], p.slots, b, &q)) return true;
  }
  return false;
}

}  // namespace swarmsim::collision
