#include "swarm/loader/paint.h"

#include <memory>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/paint/paint_layer.h"

namespace swarmsim::loader {

void AddPaintLayer(const YamlFile& file, const Field& top_field, const Field& paint,
                   const ValueReader& values, const std::optional<Region2>& arena, World* world) {
  const bool has_nozzles = !world->scene().paint_nozzles().empty();
  if (!paint.present() && !has_nozzles) return;  // no layer, no per-step cost
  paint::PaintSettings settings;
  bool area_given = false;
  if (paint.present()) {
    if (!paint.node.IsMap())
      file.Fail(paint.mark, "'paint' must be a mapping such as {resolution: 0.01} (got " +
                                Describe(paint.node) + ")");
    Fields f(file, paint, "'paint'");
    f.Expect({"resolution", "area", "background"});
    if (f.Has("resolution"))
      settings.resolution = values.Number(f.Get("resolution"), kPositiveLength);
    if (f.Has("background")) settings.background = values.Vector3(f.Get("background"), kFraction);
    if (f.Has("area")) {
      const Field area = f.Get("area");
      if (!area.node.IsMap())
        file.Fail(area.mark,
                  "'area' must be {min: [x, y], max: [x, y]} (got " + Describe(area.node) + ")");
      Fields a(file, area, "'area'");
      a.Expect({"min", "max"});
      const std::vector<double> lo = values.Numbers(a.Require("min"), 2, 2, kCoordinate);
      const std::vector<double> hi = values.Numbers(a.Require("max"), 2, 2, kCoordinate);
      if (!(lo[0] < hi[0] && lo[1] < hi[1]))
        file.Fail(a.Get("max").mark, "'area' needs max greater than min in x and in y");
      settings.min_x = lo[0];
      settings.min_y = lo[1];
      settings.max_x = hi[0];
      settings.max_y = hi[1];
      area_given = true;
    }
  }
  if (!area_given) {
    if (!arena)
      file.Fail(paint.present() ? paint.mark : top_field.mark,
                "the paint layer (for paint nozzles) covers the arena: give an 'arena', or "
                "'paint: {area: {min: [x, y], max: [x, y]}}'");
    settings.min_x = arena->min_x;
    settings.min_y = arena->min_y;
    settings.max_x = arena->max_x;
    settings.max_y = arena->max_y;
  }
  try {
    world->AddModule("paint", &settings);  // modules/paint
  } catch (const Error& e) {
    file.Fail(paint.present() ? paint.mark : top_field.mark, e.what());
  }
}

}  // namespace swarmsim::loader
