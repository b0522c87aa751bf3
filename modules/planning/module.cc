#include "modules/planning/module.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include "framework/collections.h"
#include "framework/error.h"
#include "framework/scheduler.h"
#include "framework/world.h"
#include "modules/collision/geometry.h"
#include "modules/collision/module.h"
#include "modules/paths/rows.h"
#include "modules/planning/rows.h"

namespace swarmsim::planning {

namespace {

std::string What(const Scene& scene, uint32_t owner, const PlanningTaskRow& t) {
  return (t.where.empty() ? "" : t.where + ": ") + "planning task " +
         scene.PathOf(scene.IdAt(owner));
}

// The slot of the frame the plan moves: the object `robot` names, or the
// task's robot (model root) when it names a collection.
uint32_t FrameSlot(const Scene& scene, uint32_t owner, const PlanningTaskRow& t) {
  const ObjectId id = scene.FindObject(t.robot, scene.IdAt(owner));
  if (id.IsNull())
    throw Error(What(scene, owner, t) + ": robot '" + t.robot + "' matches no object");
  if (scene.type(id) != ObjectType::kCollection) return id.index();
  const int instance = scene.instance_of_at(owner);
  if (instance < 0)
    throw Error(What(scene, owner, t) + ": robot '" + t.robot +
                "' is a collection and the task belongs to no robot: name an object");
  return scene.instances()[instance].root.index();
}

// The box of the static shapes' centres (the arena's walls).
void DefaultBounds(const Scene& scene, Vec3* lo, Vec3* hi) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  *lo = {kInf, kInf, kInf};
  *hi = {-kInf, -kInf, -kInf};
  const auto shapes = scene.shapes();
  const auto owners = scene.shape_owners();
  for (size_t r = 0; r < shapes.size(); ++r) {
    const uint32_t slot = owners[r];
    if (!scene.alive_at(slot) || scene.instance_of_at(slot) >= 0 || shapes[r].dynamic) continue;
    const Vec3& p = scene.world_pose_at(slot).p;
    *lo = {std::min(lo->x, p.x), std::min(lo->y, p.y), std::min(lo->z, p.z)};
    *hi = {std::max(hi->x, p.x), std::max(hi->y, p.y), std::max(hi->z, p.z)};
  }
}

}  // namespace

PlanRequest PlanningModule::MakeRequest(const Scene& scene, uint32_t owner,
                                        const PlanningTaskRow& t) {
  PlanRequest r;
  r.space = t.space;
  r.turning_radius = t.turning_radius;
  r.resolution = t.resolution;
  r.time_limit = t.request_time_limit;
  r.seed = t.seed;
  r.start = scene.world_pose_at(FrameSlot(scene, owner, t));
  r.goal = t.goal;
  if (t.has_bounds) {
    r.lo = t.lo;
    r.hi = t.hi;
  } else {
    DefaultBounds(scene, &r.lo, &r.hi);
    if (!(r.lo.x < r.hi.x && r.lo.y < r.hi.y))
      throw Error(What(scene, owner, t) +
                  ": no bounds given and no static shapes (an arena) to take them from: give "
                  "'bounds'");
    r.lo.z = 0;
    r.hi.z = std::max(2.0, r.hi.z);
  }
  return r;
}

void PlanningModule::EnsurePaths(Scene* scene) {
  Rows<PlanningTaskRow>* rows = TaskRows(scene);
  ObjectType path_type;
  if (rows == nullptr || !scene->FindType(paths::kTypeName, &path_type)) return;
  for (size_t r = 0; r < rows->size(); ++r) {
    if (scene->IsValid(rows->rows[r].path)) continue;
    // A stub curve at the robot until the first plan.
    const uint32_t owner = rows->owners[r];
    const Vec3 p = scene->world_pose_at(owner).p;
    paths::PathRow path;
    path.curve = std::make_shared<const paths::PathCurve>(
        std::vector<Vec3>{p, p + Vec3{1e-3, 0, 0}}, paths::Interpolation::kLinear, false);
    const std::string name = scene->name(scene->IdAt(owner)) + "_path";
    const ObjectId id = scene->AddObject(path_type, name, {}, Pose{}, &path);
    TaskRows(scene)->rows[r].path = id;  // AddObject may have moved rows
  }
}

void PlanningModule::Start(World* world) { EnsurePaths(&world->scene()); }

void PlanningModule::Actuate(World* world) {
  Scene& scene = world->scene();
  Rows<PlanningTaskRow>* rows = TaskRows(&scene);
  if (rows == nullptr) return;
  std::vector<uint32_t> pending;
  for (uint32_t r = 0; r < rows->size(); ++r)
    if (rows->rows[r].requested) pending.push_back(r);
  if (pending.empty()) return;
  EnsurePaths(&scene);
  rows = TaskRows(&scene);
  auto* collision =
      dynamic_cast<collision::CollisionModule*>(world->find_module(collision::kModuleName));
  if (collision == nullptr)
    throw Error("planning needs the collision module, which is not running");
  const collision::Geometry& geometry = collision->Fresh(*world);
  // Each task's request, robot shapes and obstacles, resolved serially.
  struct Job {
    PlanRequest request;
    std::vector<uint32_t> shapes;
    collision::Target target;
    std::vector<uint32_t> obstacle_slots;
    uint32_t frame = 0;
    PlanResult result;
  };
  std::vector<Job> jobs(pending.size());
  for (size_t k = 0; k < pending.size(); ++k) {
    const uint32_t owner = rows->owners[pending[k]];
    const PlanningTaskRow& t = rows->rows[pending[k]];
    Job& job = jobs[k];
    const std::string what = What(scene, owner, t);
    job.request = MakeRequest(scene, owner, t);
    job.frame = FrameSlot(scene, owner, t);
    job.shapes = geometry.ShapesOf(scene, EntitySlots(scene, t.robot, scene.IdAt(owner), what));
    const EntitySpec e = ParseEntity(t.obstacles);
    job.target.kind = e.kind;
    if (e.kind == EntitySpec::kPath)
      job.obstacle_slots =
          geometry.ShapesOf(scene, EntitySlots(scene, e.path, scene.IdAt(owner), what,
                                               Missing::kNone));  // a removed robot: none
  }
  // The plans, one task per worker at a time (a plan is long), on OMPL's
  // module, opened here the first time (a missing one is an error here).
  LoadPlanner();
  world->scheduler().ParallelFor(
      0, static_cast<int64_t>(jobs.size()), 1, [&](int64_t begin, int64_t end) {
        for (int64_t k = begin; k < end; ++k) {
          Job& job = jobs[k];
          job.target.slots = job.obstacle_slots;
          collision::Probe probe(geometry, scene, job.shapes, scene.world_pose_at(job.frame));
          job.result = Plan(job.request,
                            [&](const Pose& X_WR) { return !probe.Collides(X_WR, job.target); });
        }
      });
  // Results in row order; a solved plan becomes its path's curve.
  Rows<paths::PathRow>* path_rows = paths::PathRows(&scene);
  for (size_t k = 0; k < pending.size(); ++k) {
    PlanningTaskRow& t = rows->rows[pending[k]];
    PlanResult& result = jobs[k].result;
    t.requested = false;
    t.status = result.status;
    t.reason = std::move(result.reason);
    t.iterations = result.iterations;
    if (result.status != PlanStatus::kSolved) continue;
    t.waypoints = std::move(result.waypoints);
    t.dense = std::move(result.dense);
    std::vector<Vec3> points;
    for (const Pose& X : t.dense)
      if (points.empty() || (X.p - points.back()).Norm() > 1e-9) points.push_back(X.p);
    if (points.size() < 2) points.push_back(points.back() + Vec3{1e-3, 0, 0});
    paths::PathRow& path = path_rows->rows[scene.row_at(t.path.index())];
    path.curve = std::make_shared<const paths::PathCurve>(std::move(points),
                                                          paths::Interpolation::kLinear, false);
    path.position = 0;
  }
}

}  // namespace swarmsim::planning
