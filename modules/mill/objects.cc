// The `mill` and `cuttable` object types (rows.h) and the module's
// registration.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "modules/mill/mill.h"
#include "modules/mill/module.h"
#include "modules/mill/rows.h"

namespace swarmsim::mill {

// The Lua area of both types (lua_api_mill.cc).
void RegisterMillApi(lua_State* L);

namespace {

constexpr double kDeg = 3.141592653589793 / 180;

constexpr ObjectKey kMillKeys[] = {
    {"volume", "cylinder", "cone, cylinder, pyramid, disc or box, along the mill's +z"},
    {"range", "0.05", "m, > 0: the volume's length along +z (cone, disc: its radius)"},
    {"angle_deg", "30", "half-angle: cone (above 0, below 90), disc (above 0, up to 90)"},
    {"radius", "0.01", "m, > 0: cylinder"},
    {"width", "0.02", "m, > 0: box, pyramid (at the far end): along the mill's x"},
    {"height", "0.02", "m, > 0: box, pyramid (at the far end): along the mill's y"},
    {"thickness", "0.005", "m, > 0: disc, along the mill's x"},
    {"enabled", "true", "cuts from the first step"},
    {"record", "true", "write the volume removed each step to metrics.csv"},
};

constexpr ObjectKey kCuttableKeys[] = {
    {"size", "[0.1, 0.1, 0.1]", "[x, y, z] m, > 0: the block, a box centred on the object"},
    {"resolution", "0.005", "m, > 0: voxel edge (at most 50 million voxels per block)"},
    {"color", "[0.6, 0.45, 0.3]", "RGB, each 0..1"},
    {"record", "true", "write the volume left each step to metrics.csv"},
};

// A half-angle in degrees: above 0, below (or up to) `max_deg`.
double ReadAngle(const ObjectReader& r, const char* key, double max_deg, bool max_inclusive) {
  const double a = r.Number(key, kAngleDeg);
  if (!(a > 0 && (max_inclusive ? a <= max_deg : a < max_deg))) {
    char message[160];
    std::snprintf(message, sizeof message, "'%s' must be above 0 and %s %g degrees (got %g)", key,
                  max_inclusive ? "up to" : "below", max_deg, a);
    r.Fail(key, message);
  }
  return a * kDeg;
}

void ReadMill(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  MillRow& m = *static_cast<MillRow*>(row);
  Volume& v = m.volume;
  static const std::vector<std::string> kVolumes = {"cone", "cylinder", "pyramid", "disc", "box"};
  if (r.Has("volume")) {
    const std::string name = r.Choice("volume", kVolumes);
    for (size_t i = 0; i < kVolumes.size(); ++i)
      if (name == kVolumes[i]) v.kind = static_cast<VolumeKind>(i);
  }
  using K = VolumeKind;
  const K k = v.kind;
  // Each size applies to some volumes: elsewhere it is an error.
  const auto applies = [&](const char* key, bool ok, const char* where) {
    if (!r.Has(key)) return false;
    if (!ok)
      r.FailAtKey(key, std::string("'") + key + "' applies to " + where +
                           " mills only (this is a " + ToString(k) + ")");
    return true;
  };
  if (r.Has("range")) v.range = r.Number("range", kPositiveLength);
  if (applies("angle_deg", k == K::kCone || k == K::kDisc, "cone and disc"))
    v.angle = ReadAngle(r, "angle_deg", 90, k == K::kDisc);
  if (applies("radius", k == K::kCylinder, "cylinder"))
    v.radius = r.Number("radius", kPositiveLength);
  if (applies("width", k == K::kBox || k == K::kPyramid, "box and pyramid"))
    v.width = r.Number("width", kPositiveLength);
  if (applies("height", k == K::kBox || k == K::kPyramid, "box and pyramid"))
    v.height = r.Number("height", kPositiveLength);
  if (applies("thickness", k == K::kDisc, "disc"))
    v.thickness = r.Number("thickness", kPositiveLength);
  if (r.Has("enabled")) m.enabled = r.Bool("enabled");
  if (r.Has("record")) m.record = r.Bool("record");
}

void ReadCuttable(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  CuttableRow& c = *static_cast<CuttableRow*>(row);
  if (r.Has("size")) c.size = r.Vector3("size", kPositiveLength);
  if (r.Has("resolution")) c.resolution = r.Number("resolution", kPositiveLength);
  if (r.Has("color")) c.color = r.Vector3("color", kFraction);
  if (r.Has("record")) c.record = r.Bool("record");
  // The grid, counted before anything is allocated.
  const double n[3] = {std::max(1.0, std::ceil(c.size.x / c.resolution - 1e-9)),
                       std::max(1.0, std::ceil(c.size.y / c.resolution - 1e-9)),
                       std::max(1.0, std::ceil(c.size.z / c.resolution - 1e-9))};
  const double count = n[0] * n[1] * n[2];
  if (count > kMaxVoxels) {
    char message[256];
    std::snprintf(message, sizeof message,
                  "the block would have %.0f x %.0f x %.0f = %.0f voxels, more than %.0f; use a "
                  "coarser resolution or a smaller size",
                  n[0], n[1], n[2], count, kMaxVoxels);
    r.Fail(r.Has("resolution") ? "resolution" : "size", message);
  }
  c.nx = static_cast<uint32_t>(n[0]);
  c.ny = static_cast<uint32_t>(n[1]);
  c.nz = static_cast<uint32_t>(n[2]);
  c.remaining = c.voxel_count();
  c.digest = 0;
}

// A copy starts afresh: a mill with no reading, a cuttable as a full block.
void CopyMill(const void* source, void* row) {
  const MillRow& from = *static_cast<const MillRow*>(source);
  MillRow& to = *static_cast<MillRow*>(row);
  to.volume = from.volume;
  to.enabled = from.enabled;
  to.record = from.record;
}

void CopyCuttable(const void* source, void* row) {
  CuttableRow& to = *static_cast<CuttableRow*>(row);
  to = *static_cast<const CuttableRow*>(source);
  to.remaining = to.voxel_count();
  to.digest = 0;
}

void ScaleMill(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  Volume& v = static_cast<MillRow*>(row)->volume;
  v.range *= s;
  v.radius *= s;
  v.width *= s;
  v.height *= s;
  v.thickness *= s;
}

// The grid stays: the voxels (and what was cut) scale with the block.
void ScaleCuttable(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  CuttableRow& c = *static_cast<CuttableRow*>(row);
  c.size = c.size * s;
  c.resolution *= s;
}

void HashMills(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<MillRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    const MillRow& m = rows.rows[r];
    h->AddValue(rows.owners[r]);
    h->AddValue(m.enabled);
    h->AddValue(m.removed);
    h->AddValue(m.removed_total);
  }
}

void HashCuttables(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<CuttableRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    h->AddValue(rows.owners[r]);
    h->AddValue(rows.rows[r].remaining);
    h->AddValue(rows.rows[r].digest);
  }
}

std::shared_ptr<const ObjectTypeDescriptor> MillType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = "mill";
  t->description = "a convex cutting volume that removes cuttable voxels and map voxels each step";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<MillRow>>();
  };
  t->copy_row = CopyMill;
  t->scale_row = ScaleMill;
  t->hash_rows = HashMills;
  t->keys = kMillKeys;
  t->read = ReadMill;
  t->register_lua = RegisterMillApi;
  return t;
}

std::shared_ptr<const ObjectTypeDescriptor> CuttableType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = "cuttable";
  t->description = "a block of material as voxels, which mills cut";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<CuttableRow>>();
  };
  t->copy_row = CopyCuttable;
  t->scale_row = ScaleCuttable;
  t->hash_rows = HashCuttables;
  t->keys = kCuttableKeys;
  t->read = ReadCuttable;
  return t;
}

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"calculation", kModuleName, "1.0",
        "mills cutting voxel blocks and the environment map (mill, cuttable types)"},
       PhaseBit(Phase::kPhysics) | PhaseBit(Phase::kRecord),
       40,
       /*every_world=*/true,
       [](World* world, const void*) { return std::make_unique<MillModule>(world); }});
  registry->RegisterObjectType(MillType());
  registry->RegisterObjectType(CuttableType());
}

}  // namespace swarmsim::mill
