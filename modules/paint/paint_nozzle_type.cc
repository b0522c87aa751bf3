// paint_nozzle: marks the floor paint layer under it each step while enabled
// (modules/paint).
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/world_state.h"
#include "modules/paint/paint_nozzle.h"
#include "modules/paint/paint_type.h"

namespace swarmsim::paint {

// Its Lua API area (lua_api_paint.cc).
void RegisterPaintApi(lua_State* L);

namespace {

constexpr ObjectKey kKeys[] = {
    {"color", "[0.1, 0.1, 0.8]", "RGB, each 0..1"},
    {"radius", "0.02", "m, of the painted disc"},
    {"enabled", "true", "paints from the first step"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<PaintNozzleData>>();
}

void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  static_cast<PaintNozzleData*>(row)->radius *= s;
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  PaintNozzleData& n = *static_cast<PaintNozzleData*>(row);
  if (r.Has("color")) n.color = r.Vector3("color", kFraction);
  if (r.Has("radius")) n.radius = r.Number("radius", kPositiveLength);
  if (r.Has("enabled")) n.enabled = r.Bool("enabled");
}

// Snapshots: what scripts change (sim.setPaintNozzle): colour and switch.
void Save(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const PaintNozzleData& n : scene.rows<PaintNozzleData>(type).rows) {
    out->Put(n.color);
    out->Put<uint8_t>(n.enabled);
  }
}

void Load(Scene* scene, ObjectType type, StateReader* in) {
  for (PaintNozzleData& n : scene->rows<PaintNozzleData>(type).rows) {
    n.color = in->Get<Vec3>();
    n.enabled = in->GetBool();
  }
}

}  // namespace

constinit const ObjectTypeDescriptor kPaintNozzleType{
    .name = "paint_nozzle",
    .description = "marks the floor paint layer under it while enabled",
    .make_rows = MakeRows,
    .scale_row = Scale,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterPaintApi,
    .save_rows = Save,
    .load_rows = Load,
};

}  // namespace swarmsim::paint
