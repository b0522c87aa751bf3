// The `distance` and `collision` object types (rows.h) and the module's
// registration.
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "modules/collision/collision.h"
#include "modules/collision/module.h"
#include "modules/collision/rows.h"

namespace swarmsim::collision {

// The Lua area of both types (lua_api_collision.cc).
void RegisterCollisionApi(lua_State* L);

namespace {

constexpr ObjectKey kDistanceKeys[] = {
    {"between", "required",
     "[A, B]: A an object path or collection, B the same, `environment` or `everything_else`"},
    {"threshold", "none", "m, > 0: nothing farther is measured (faster)"},
    {"record", "true", "write the distance and the two closest points to metrics.csv"},
};

constexpr ObjectKey kCollisionKeys[] = {
    {"between", "required",
     "[A, B]: A an object path or collection, B the same, `environment` or `everything_else`"},
    {"contacts", "0", "contact points to keep (the collision contour), 0..64"},
    {"record", "true", "write the colliding flag (and contact count) to metrics.csv"},
};

void ReadBetween(const ObjectReader& r, std::string* entities, std::string* where) {
  *where = r.Where("between");
  const std::vector<std::string> between = r.Strings("between", 2, /*required=*/true);
  if (between.size() != 2)
    r.Fail("between",
           "'between' takes two entities, [A, B] (got " + std::to_string(between.size()) + ")");
  for (int i = 0; i < 2; ++i) {
    const EntitySpec e = ParseEntity(between[i]);
    if (e.kind == EntitySpec::kPath &&
        (e.path.empty() || (e.path[0] != '/' && e.path[0] != ':' && e.path[0] != '.')))
      r.Fail("between", "'" + between[i] +
                            "' is neither an object path ('/...', ':...', './...') nor "
                            "'environment' or 'everything_else'");
    if (i == 0 && e.kind != EntitySpec::kPath)
      r.Fail("between", "the first entity must be an object or a collection ('" + between[i] +
                            "' may come second)");
    entities[i] = between[i];
  }
}

void ReadDistance(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  DistanceRow& d = *static_cast<DistanceRow*>(row);
  ReadBetween(r, d.entity, &d.where);
  if (r.Has("threshold")) d.threshold = r.Number("threshold", kPositiveLength);
  if (r.Has("record")) d.record = r.Bool("record");
}

void ReadCollision(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  CollisionRow& c = *static_cast<CollisionRow*>(row);
  ReadBetween(r, c.entity, &c.where);
  if (r.Has("contacts")) c.contacts = static_cast<int>(r.Integer("contacts", 0, 64));
  if (r.Has("record")) c.record = r.Bool("record");
}

// A copy measures afresh.
void CopyDistance(const void* source, void* row) {
  const DistanceRow& from = *static_cast<const DistanceRow*>(source);
  DistanceRow& to = *static_cast<DistanceRow*>(row);
  to.entity[0] = from.entity[0];
  to.entity[1] = from.entity[1];
  to.where = from.where;
  to.threshold = from.threshold;
  to.record = from.record;
}

void CopyCollision(const void* source, void* row) {
  const CollisionRow& from = *static_cast<const CollisionRow*>(source);
  CollisionRow& to = *static_cast<CollisionRow*>(row);
  to.entity[0] = from.entity[0];
  to.entity[1] = from.entity[1];
  to.where = from.where;
  to.contacts = from.contacts;
  to.record = from.record;
}

void ScaleDistance(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  static_cast<DistanceRow*>(row)->threshold *= s;
}

void HashDistance(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<DistanceRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    const DistanceRow& d = rows.rows[r];
    h->AddValue(rows.owners[r]);
    h->AddValue(d.found);
    h->AddValue(d.distance);
    h->AddValue(d.p1);
    h->AddValue(d.p2);
    h->AddValue(d.o1);
    h->AddValue(d.o2);
  }
}

void HashCollision(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<CollisionRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    const CollisionRow& c = rows.rows[r];
    h->AddValue(rows.owners[r]);
    h->AddValue(c.colliding);
    h->AddValue(c.o1);
    h->AddValue(c.o2);
    for (const Vec3& p : c.contact_points) h->AddValue(p);
  }
}

// Both entities name objects, and not the same ones.
void CheckBetween(const Scene& scene, ObjectId id, const std::string* entities,
                  const std::string& where, const char* type) {
  const std::string what =
      (where.empty() ? "" : where + ": ") + type + " object " + scene.PathOf(id);
  std::vector<uint32_t> slots[2];
  for (int i = 0; i < 2; ++i) {
    const EntitySpec e = ParseEntity(entities[i]);
    if (e.kind == EntitySpec::kPath) slots[i] = EntitySlots(scene, e.path, id, what);
  }
  if (ParseEntity(entities[1]).kind == EntitySpec::kPath && slots[0] == slots[1])
    throw Error(what + ": '" + entities[0] + "' and '" + entities[1] +
                "' are the same objects: nothing to measure between them");
}

void CheckDistance(const Scene& scene, ObjectId id, const void* row) {
  const DistanceRow& d = *static_cast<const DistanceRow*>(row);
  CheckBetween(scene, id, d.entity, d.where, "distance");
}

void CheckCollision(const Scene& scene, ObjectId id, const void* row) {
  const CollisionRow& c = *static_cast<const CollisionRow*>(row);
  CheckBetween(scene, id, c.entity, c.where, "collision");
}

std::shared_ptr<const ObjectTypeDescriptor> DistanceType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = "distance";
  t->description = "a minimum-distance object between two entities, measured after each step";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<DistanceRow>>();
  };
  t->copy_row = CopyDistance;
  t->scale_row = ScaleDistance;
  t->hash_rows = HashDistance;
  t->keys = kDistanceKeys;
  t->read = ReadDistance;
  t->check = CheckDistance;
  t->register_lua = RegisterCollisionApi;
  return t;
}

std::shared_ptr<const ObjectTypeDescriptor> CollisionType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = "collision";
  t->description = "a collision object between two entities, checked after each step";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<CollisionRow>>();
  };
  t->copy_row = CopyCollision;
  t->hash_rows = HashCollision;
  t->keys = kCollisionKeys;
  t->read = ReadCollision;
  t->check = CheckCollision;
  return t;
}

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"calculation", kModuleName, "1.0",
        "collision and minimum-distance objects on FCL 0.7 (distance, collision types)"},
       PhaseBit(Phase::kPhysics) | PhaseBit(Phase::kRecord),
       50,
       /*every_world=*/true,
       [](World*, const void*) { return std::make_unique<CollisionModule>(); }});
  registry->RegisterObjectType(DistanceType());
  registry->RegisterObjectType(CollisionType());
}

}  // namespace swarmsim::collision
