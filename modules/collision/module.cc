#include "modules/collision/module.h"

#include <algorithm>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/world.h"
#include "modules/collision/rows.h"

namespace swarmsim::collision {

namespace {

template <typename Row>
Rows<Row>* TableOf(Scene* scene, const char* type_name) {
  ObjectType type;
  if (!scene->FindType(type_name, &type)) return nullptr;
  return static_cast<Rows<Row>*>(scene->rows(type));
}

}  // namespace

bool CollisionModule::HasObjects(Scene* scene) {
  const auto* d = TableOf<DistanceRow>(scene, "distance");
  const auto* c = TableOf<CollisionRow>(scene, "collision");
  return (d != nullptr && d->size() > 0) || (c != nullptr && c->size() > 0);
}

// After physics: the step count is already the next step's, the one whose
// scripts query next.
void CollisionModule::Refresh(const World& world) {
  std::lock_guard lock(mutex_);
  geometry_.Refresh(world.scene());
  step_.store(static_cast<uint64_t>(world.step_count()), std::memory_order_release);
  version_.store(world.scene().structure_version(), std::memory_order_release);
}

const Geometry& CollisionModule::Fresh(const World& world) {
  const Scene& scene = world.scene();
  const uint64_t step = static_cast<uint64_t>(world.step_count());
  if (version_.load(std::memory_order_acquire) != scene.structure_version() ||
      step_.load(std::memory_order_acquire) != step) {
    std::lock_guard lock(mutex_);
    if (version_.load(std::memory_order_relaxed) != scene.structure_version() ||
        step_.load(std::memory_order_relaxed) != step) {
      geometry_.Refresh(scene);
      step_.store(step, std::memory_order_release);
      version_.store(scene.structure_version(), std::memory_order_release);
    }
  }
  return geometry_;
}

void CollisionModule::Resolve(const Scene& scene) {
  // The first time, a path that names nothing is an error (worlds the
  // loader did not check); later it named a robot removed since: empty.
  const Missing missing = jobs_version_ == UINT64_MAX ? Missing::kError : Missing::kNone;
  jobs_.assign(scene.instances().size() + 1, {});
  any_jobs_ = false;
  Scene& s = const_cast<Scene&>(scene);
  const auto add = [&](const char* type_name, bool distance, const std::string* entities,
                       uint32_t row, uint32_t owner) {
    const ObjectId from = scene.IdAt(owner);
    const std::string& where = distance ? TableOf<DistanceRow>(&s, "distance")->rows[row].where
                                        : TableOf<CollisionRow>(&s, "collision")->rows[row].where;
    const std::string what = (where.empty() ? "" : where + ": ") + std::string(type_name) +
                             " object " + scene.PathOf(from);
    Job job;
    job.distance = distance;
    job.row = row;
    const EntitySpec first = ParseEntity(entities[0]);
    if (first.kind != EntitySpec::kPath)
      throw Error(what +
                  ": the first entity of 'between' must be an object or a collection (got '" +
                  entities[0] + "'); '" + entities[0] + "' may come second");
    job.a = geometry_.ShapesOf(scene, EntitySlots(scene, first.path, from, what, missing));
    const EntitySpec second = ParseEntity(entities[1]);
    job.kind = second.kind;
    if (second.kind == EntitySpec::kPath)
      job.b = geometry_.ShapesOf(scene, EntitySlots(scene, second.path, from, what, missing));
    const int instance = scene.instance_of_at(owner);
    jobs_[instance >= 0 ? instance : jobs_.size() - 1].push_back(std::move(job));
    any_jobs_ = true;
  };
  if (auto* rows = TableOf<DistanceRow>(&s, "distance"))
    for (uint32_t r = 0; r < rows->size(); ++r)
      add("distance", true, rows->rows[r].entity, r, rows->owners[r]);
  if (auto* rows = TableOf<CollisionRow>(&s, "collision"))
    for (uint32_t r = 0; r < rows->size(); ++r)
      add("collision", false, rows->rows[r].entity, r, rows->owners[r]);
}

void CollisionModule::Run(Scene* scene, const Job& job) {
  const Target target{job.kind, job.b};
  if (job.distance) {
    DistanceRow& row = TableOf<DistanceRow>(scene, "distance")->rows[job.row];
    const DistanceAnswer d = geometry_.Distance(job.a, target, row.threshold, row.hint1, row.hint2);
    row.found = d.found;
    row.distance = d.found ? d.distance : INFINITY;
    row.p1 = d.found ? d.p1 : Vec3{};
    row.p2 = d.found ? d.p2 : Vec3{};
    row.o1 = d.found ? scene->IdAt(d.s1) : ObjectId{};
    row.o2 = d.found && d.s2 < scene->slot_count() ? scene->IdAt(d.s2) : ObjectId{};
    row.hint1 = d.s1;
    row.hint2 = d.s2;
  } else {
    CollisionRow& row = TableOf<CollisionRow>(scene, "collision")->rows[job.row];
    CollisionAnswer c = geometry_.Collide(job.a, target, row.contacts);
    row.colliding = c.colliding;
    row.o1 = c.colliding ? scene->IdAt(c.s1) : ObjectId{};
    row.o2 = c.colliding && c.s2 < scene->slot_count() ? scene->IdAt(c.s2) : ObjectId{};
    row.contact_points = std::move(c.contacts);
  }
}

void CollisionModule::Compute(World* world) {
  Scene& scene = world->scene();
  bool refreshed = false;
  if (jobs_version_ != scene.structure_version()) {
    any_jobs_ = HasObjects(&scene);
    if (any_jobs_) {
      Refresh(*world);  // ShapesOf reads the geometry's shapes
      Resolve(scene);
      refreshed = true;
    }
    jobs_version_ = scene.structure_version();
  }
  if (!any_jobs_) return;
  if (!refreshed) Refresh(*world);
  const int64_t robots = static_cast<int64_t>(jobs_.size()) - 1;
  world->scheduler().ParallelFor(0, robots, kRobotGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r)
      for (const Job& job : jobs_[r]) Run(&scene, job);
  });
  for (const Job& job : jobs_.back()) Run(&scene, job);
}

void CollisionModule::Start(World* world) { Compute(world); }

void CollisionModule::AfterPhysics(World* world) { Compute(world); }

void CollisionModule::Record(const World& world, std::vector<MetricSample>* out) {
  if (!any_jobs_) return;
  Scene& scene = const_cast<Scene&>(world.scene());
  const auto sample = [&](uint32_t owner, const std::string& suffix, double value) {
    out->push_back({world.step_count(), world.time(), scene.instance_of_at(owner),
                    scene.name(scene.IdAt(owner)) + suffix, value});
  };
  if (auto* rows = TableOf<DistanceRow>(&scene, "distance")) {
    for (uint32_t r = 0; r < rows->size(); ++r) {
      const DistanceRow& d = rows->rows[r];
      if (!d.record) continue;
      const uint32_t owner = rows->owners[r];
      sample(owner, ".distance", d.distance);
      if (!d.found) continue;
      const double v[6] = {d.p1.x, d.p1.y, d.p1.z, d.p2.x, d.p2.y, d.p2.z};
      const char* names[6] = {".x1", ".y1", ".z1", ".x2", ".y2", ".z2"};
      for (int i = 0; i < 6; ++i) sample(owner, names[i], v[i]);
    }
  }
  if (auto* rows = TableOf<CollisionRow>(&scene, "collision")) {
    for (uint32_t r = 0; r < rows->size(); ++r) {
      const CollisionRow& c = rows->rows[r];
      if (!c.record) continue;
      sample(rows->owners[r], ".colliding", c.colliding ? 1 : 0);
      if (c.contacts > 0)
        sample(rows->owners[r], ".contacts", static_cast<double>(c.contact_points.size()));
    }
  }
}

}  // namespace swarmsim::collision
