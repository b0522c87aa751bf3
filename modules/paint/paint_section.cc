// The world file's `paint:` section (worlds/README.md), the paint module's
// own: the floor paint layer that paint nozzles mark, written to the run's
// outputs as paint.png. Read through the loader's ObjectReader after the
// world's objects exist; a world with paint nozzles gets a layer with the
// defaults even without the key, and its area defaults to the arena's inner
// area. Over a floor (`floor:`, read before this section), the layer starts
// from the floor, and its area, resolution and background are the floor's.
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/floor_layer.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "framework/world_section.h"
#include "modules/paint/paint_layer.h"
#include "modules/paint/paint_nozzle.h"
#include "modules/paint/paint_type.h"

namespace swarmsim::paint {

namespace {

constexpr ObjectKey kKeys[] = {
    {"resolution", "0.01 (with a floor: the floor's)",
     "m, side of one pixel (at most 100 megapixels)"},
    {"area", "the arena's inner area (with a floor: the floor's)",
     "{min: [x, y], max: [x, y]} m, the floor covered (required without an arena)"},
    {"background", "[1, 1, 1]",
     "RGB 0..1, the unpainted floor (with a `floor:` section: the floor, and this key is refused)"},
};

bool HasNozzles(const Scene& scene) {
  ObjectType type;
  return scene.FindType(kPaintNozzleTypeName, &type) &&
         !scene.rows<PaintNozzleData>(type).rows.empty();
}

// area: {min: [x, y], max: [x, y]}
void ReadArea(const ObjectReader& paint, PaintSettings* settings) {
  const std::unique_ptr<ObjectReader> area =
      paint.Map("area", "'area'", "{min: [x, y], max: [x, y]}");
  if (!area) paint.Fail("area", "'area' must be {min: [x, y], max: [x, y]} (got nothing)");
  const std::vector<std::string> keys = {"min", "max"};
  area->Expect(keys);
  area->Require("min");
  const std::vector<double> lo = area->Numbers("min", 2, 2, kCoordinate);
  area->Require("max");
  const std::vector<double> hi = area->Numbers("max", 2, 2, kCoordinate);
  if (!(lo[0] < hi[0] && lo[1] < hi[1]))
    area->Fail("max", "'area' needs max greater than min in x and in y");
  settings->min_x = lo[0];
  settings->min_y = lo[1];
  settings->max_x = hi[0];
  settings->max_y = hi[1];
}

void ReadPaint(const ObjectReader& top, const WorldSectionContext& context, World* world) {
  const std::unique_ptr<ObjectReader> paint =
      top.Map("paint", "'paint'", "a mapping such as {resolution: 0.01}");
  if (!paint && !HasNozzles(world->scene())) return;  // no layer, no per-step cost
  // Errors without a value of their own point at `paint:`, else at the file.
  const ObjectReader& where = paint ? *paint : top;
  PaintSettings settings;
  // Over a floor: its area, resolution and background unless given.
  const FloorLayer* floor = world->floor_layer();
  if (floor != nullptr) {
    const FloorArea a = floor->floor_area();
    settings.resolution = a.resolution;
    settings.background = a.background;
  }
  bool area_given = false;
  if (paint) {
    const std::vector<std::string> keys = {"resolution", "area", "background"};
    paint->Expect(keys);
    if (floor != nullptr && paint->Has("background"))
      paint->FailAtKey("background",
                       "the unpainted floor is the world's 'floor:' (its background is the "
                       "floor's 'background'); remove 'background' from 'paint'");
    if (paint->Has("resolution"))
      settings.resolution = paint->Number("resolution", kPositiveLength);
    if (paint->Has("background")) settings.background = paint->Vector3("background", kFraction);
    if (paint->Has("area")) {
      ReadArea(*paint, &settings);
      area_given = true;
    }
  }
  if (!area_given && floor != nullptr) {
    const FloorArea a = floor->floor_area();
    settings.min_x = a.min_x, settings.min_y = a.min_y, settings.max_x = a.max_x,
    settings.max_y = a.max_y;
  } else if (!area_given) {
    if (!context.arena)
      where.FailHere(
          "the paint layer (for paint nozzles) covers the arena: give an 'arena', or "
          "'paint: {area: {min: [x, y], max: [x, y]}}'");
    settings.min_x = context.arena->min_x;
    settings.min_y = context.arena->min_y;
    settings.max_x = context.arena->max_x;
    settings.max_y = context.arena->max_y;
  }
  try {
    world->AddModule("paint", &settings);
  } catch (const Error& e) {
    where.FailHere(e.what());
  }
}

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterObjectType(std::make_shared<const ObjectTypeDescriptor>(kPaintNozzleType));
  registry->RegisterModule(PaintModule());
}

std::shared_ptr<const WorldSectionDescriptor> PaintSection() {
  auto section = std::make_shared<WorldSectionDescriptor>();
  section->key = "paint";
  section->doc = "the floor paint layer paint nozzles mark (paint.png)";
  section->keys = kKeys;
  section->read = ReadPaint;
  return section;
}

}  // namespace swarmsim::paint
