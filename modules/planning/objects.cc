// The `planning_task` object type (rows.h) and the module's registration.
#include <memory>
#include <string>
#include <vector>

#include "framework/collections.h"
#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "modules/planning/module.h"
#include "modules/planning/planning.h"
#include "modules/planning/rows.h"

namespace swarmsim::planning {

// The Lua area of the type (lua_api_planning.cc).
void RegisterPlanningApi(lua_State* L);

namespace {

constexpr ObjectKey kTaskKeys[] = {
    {"space", "se2",
     "`se2` or `se3` (holonomic, RRT-Connect), `dubins` or `reeds_shepp` (car-like with a "
     "turning radius, RRT)"},
    {"robot", ":",
     "the object whose pose is planned, with the shapes below it (`:` the task's robot); or a "
     "collection of the shapes that move with the robot"},
    {"obstacles", "environment",
     "`environment` (static shapes and the map), `everything_else` (also other robots as they "
     "stand) or an object path or collection"},
    {"bounds", "the arena",
     "[xmin, ymin, xmax, ymax] (planar) or [xmin, ymin, zmin, xmax, ymax, zmax] (se3), m, world "
     "frame: where the robot's frame may go; default: the box of the static shapes' centres "
     "(inside the arena's walls)"},
    {"turning_radius", "0.5", "m, > 0: the car's smallest turning radius (dubins, reeds_shepp)"},
    {"resolution", "0.05", "m, >= 0.0001: motions are checked for collisions every this far"},
    {"time_limit", "1",
     "s, > 0: the planning budget, counted in planner iterations (20,000 per second), never "
     "the wall clock, so results do not depend on the machine's load"},
};

constexpr NumberRule kTimeLimit{"a positive number of seconds", 0, 3600, true};
// Motions are checked every `resolution` m: below 0.1 mm a plan across a
// yard would check millions of states a motion (QA: 1e-9 grew to 800 MB).
constexpr double kMinResolution = 1e-4;
constexpr NumberRule kResolution{"a number of metres from 0.0001", kMinResolution, kMaxLength};

void ReadTask(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  PlanningTaskRow& t = *static_cast<PlanningTaskRow*>(row);
  t.where = r.Has("robot") ? r.Where("robot") : "";
  if (r.Has("space")) {
    const std::string space = r.Choice("space", {"se2", "se3", "dubins", "reeds_shepp"});
    ParseSpace(space, &t.space);
  }
  if (r.Has("robot")) {
    t.robot = r.String("robot");
    if (t.robot.empty() || (t.robot[0] != '/' && t.robot[0] != ':' && t.robot[0] != '.'))
      r.Fail("robot", "'" + t.robot + "' is not an object path ('/...', ':...', './...')");
  }
  if (r.Has("obstacles")) {
    t.obstacles = r.String("obstacles");
    const EntitySpec e = ParseEntity(t.obstacles);
    if (e.kind == EntitySpec::kPath &&
        (e.path.empty() || (e.path[0] != '/' && e.path[0] != ':' && e.path[0] != '.')))
      r.Fail("obstacles", "'" + t.obstacles +
                              "' is neither an object path ('/...', ':...', './...') nor "
                              "'environment' or 'everything_else'");
  }
  if (r.Has("bounds")) {
    const size_t n = IsPlanar(t.space) ? 4 : 6;
    const std::vector<double> b = r.Numbers("bounds", n, n, kCoordinate);
    t.has_bounds = true;
    if (n == 4) {
      t.lo = {b[0], b[1], 0};
      t.hi = {b[2], b[3], 0};
    } else {
      t.lo = {b[0], b[1], b[2]};
      t.hi = {b[3], b[4], b[5]};
    }
    if (!(t.lo.x < t.hi.x && t.lo.y < t.hi.y && (n == 4 || t.lo.z < t.hi.z)))
      r.Fail("bounds",
             "each minimum must be below its maximum ([xmin, ymin, xmax, ymax]" +
                 std::string(n == 4 ? "" : " with z: [xmin, ymin, zmin, xmax, ymax, zmax]") + ")");
  }
  if (r.Has("turning_radius")) t.turning_radius = r.Number("turning_radius", kPositiveLength);
  if (r.Has("resolution")) t.resolution = r.Number("resolution", kResolution);
  if (r.Has("time_limit")) t.time_limit = r.Number("time_limit", kTimeLimit);
  if (t.where.empty()) t.where = r.Where(r.Has("space") ? "space" : "time_limit");
}

// A copy has the settings only: its own result path, no plan yet.
void CopyTask(const void* source, void* row) {
  const PlanningTaskRow& from = *static_cast<const PlanningTaskRow*>(source);
  PlanningTaskRow& to = *static_cast<PlanningTaskRow*>(row);
  to = PlanningTaskRow{};
  to.space = from.space;
  to.robot = from.robot;
  to.obstacles = from.obstacles;
  to.has_bounds = from.has_bounds;
  to.lo = from.lo;
  to.hi = from.hi;
  to.turning_radius = from.turning_radius;
  to.resolution = from.resolution;
  to.time_limit = from.time_limit;
  to.where = from.where;
}

void ScaleTask(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  PlanningTaskRow& t = *static_cast<PlanningTaskRow*>(row);
  t.turning_radius *= s;
  t.resolution *= s;
}

void HashTasks(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<PlanningTaskRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    const PlanningTaskRow& t = rows.rows[r];
    h->AddValue(rows.owners[r]);
    h->AddValue(static_cast<uint8_t>(t.status));
    h->AddValue(t.iterations);
    h->AddValue(t.path);
    for (const Pose& X : t.waypoints) h->AddValue(X);
    h->AddValue(static_cast<uint64_t>(t.dense.size()));
  }
}

// The robot and obstacle paths name objects.
void CheckTask(const Scene& scene, ObjectId id, const void* row) {
  const PlanningTaskRow& t = *static_cast<const PlanningTaskRow*>(row);
  const std::string what =
      (t.where.empty() ? "" : t.where + ": ") + "planning task " + scene.PathOf(id);
  EntitySlots(scene, t.robot, id, what);
  const EntitySpec e = ParseEntity(t.obstacles);
  if (e.kind == EntitySpec::kPath) EntitySlots(scene, e.path, id, what);
}

std::shared_ptr<const ObjectTypeDescriptor> TaskType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = kTypeName;
  t->description =
      "a path-planning task (OMPL): a robot's shapes planned through the scene from Lua";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<PlanningTaskRow>>();
  };
  t->copy_row = CopyTask;
  t->scale_row = ScaleTask;
  t->hash_rows = HashTasks;
  t->keys = kTaskKeys;
  t->read = ReadTask;
  t->check = CheckTask;
  t->register_lua = RegisterPlanningApi;
  return t;
}

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"calculation", kModuleName, "1.0",
        "path planning on OMPL 1.5 (planning_task type): RRT-Connect (se2, se3), RRT (dubins, "
        "reeds_shepp), robots in parallel, deterministic"},
       PhaseBit(Phase::kActuate),
       60,
       /*every_world=*/true,
       [](World*, const void*) { return std::make_unique<PlanningModule>(); }});
  registry->RegisterObjectType(TaskType());
}

}  // namespace swarmsim::planning
