// The world file's `floor:` section (worlds/README.md), the floor module's
// own: a background colour, a PNG image placed by its corners, and shapes
// drawn over it, read through the loader's ObjectReader once the world's
// objects exist; every error names file:line:column.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "framework/world_section.h"
#include "modules/floor/floor.h"

namespace swarmsim::floors {

namespace {

constexpr ObjectKey kKeys[] = {
    {"area", "the arena's inner area, else the image's corners",
     "{min: [x, y], max: [x, y]} m, the floor drawn (outside it: the background)"},
    {"resolution", "0.01, or the image's pixel size if finer",
     "m, side of one pixel of the floor raster (at most 64 megapixels)"},
    {"background", "1", "a grey level 0..1 or [r, g, b], the bare floor"},
    {"image", "none",
     "{file: images/nest.png, min: [x, y], max: [x, y]}: a PNG (at most 64 megapixels, relative "
     "to the world file) and where its lower-left and upper-right corners lie (m; default: the "
     "area)"},
    {"shapes", "none",
     "a list drawn in order over the image: circle, rectangle, linear_gradient, radial_gradient"},
};

// A colour: [r, g, b] or one grey level, each 0..1.
Vec3 Color(const ObjectReader& r, const std::string& key, const Vec3& fallback) {
  if (!r.Has(key)) return fallback;
  if (r.IsList(key)) return r.Vector3(key, kFraction);
  const double g = r.Number(key, kFraction);
  return {g, g, g};
}

Vec3 Point(const ObjectReader& r, const std::string& key) {
  r.Require(key);
  const std::vector<double> p = r.Numbers(key, 2, 2, kCoordinate);
  return {p[0], p[1], 0};
}

// {min: [x, y], max: [x, y]} read from `r`'s own keys min and max.
void Corners(const ObjectReader& r, const std::string& what, Vec3* lo, Vec3* hi) {
  *lo = Point(r, "min");
  *hi = Point(r, "max");
  if (!(lo->x < hi->x && lo->y < hi->y))
    r.Fail("max", what + " needs max greater than min in x and in y");
}

FloorShape ReadShape(const ObjectReader& r) {
  static const std::vector<std::string> kinds = {"circle", "rectangle", "linear_gradient",
                                                 "radial_gradient"};
  r.Require("type");
  const std::string kind = r.Choice("type", kinds, true);
  FloorShape s;
  if (kind == "circle" || kind == "radial_gradient") {
    const std::vector<std::string> keys =
        kind == "circle"
            ? std::vector<std::string>{"type", "center", "radius", "color"}
            : std::vector<std::string>{"type", "center", "radius", "inner_color", "outer_color"};
    r.Expect(keys);
    s.kind = kind == "circle" ? FloorShape::Kind::kCircle : FloorShape::Kind::kRadialGradient;
    s.a = Point(r, "center");
    r.Require("radius");
    s.radius = r.Number("radius", kNonNegativeLength, true);
    if (kind == "circle") {
      s.color = Color(r, "color", {0, 0, 0});
    } else {
      s.color = Color(r, "inner_color", {0, 0, 0});
      s.color2 = Color(r, "outer_color", {1, 1, 1});
    }
  } else if (kind == "rectangle") {
    r.Expect(std::vector<std::string>{"type", "min", "max", "color"});
    s.kind = FloorShape::Kind::kRectangle;
    Corners(r, "a rectangle", &s.a, &s.b);
    s.color = Color(r, "color", {0, 0, 0});
  } else {
    r.Expect(
        std::vector<std::string>{"type", "from", "to", "from_color", "to_color", "min", "max"});
    s.kind = FloorShape::Kind::kLinearGradient;
    s.a = Point(r, "from");
    s.b = Point(r, "to");
    if (s.a.x == s.b.x && s.a.y == s.b.y)
      r.Fail("to", "a linear gradient needs 'to' apart from 'from'");
    s.color = Color(r, "from_color", {0, 0, 0});
    s.color2 = Color(r, "to_color", {1, 1, 1});
    if (r.Has("min") || r.Has("max")) {
      Corners(r, "a linear gradient's bounds", &s.lo, &s.hi);
      s.bounded = true;
    }
  }
  return s;
}

void ReadFloor(const ObjectReader& top, const WorldSectionContext& context, World* world) {
  const std::unique_ptr<ObjectReader> floor =
      top.Map("floor", "'floor'", "a mapping such as {background: 1, shapes: [...]}");
  if (!floor) return;  // no floor layer, no cost
  floor->Expect(std::vector<std::string>{"area", "resolution", "background", "image", "shapes"});
  FloorSettings settings;
  settings.background = Color(*floor, "background", {1, 1, 1});
  // The image: its file, then where its corners lie.
  bool image_placed = false;
  if (floor->Has("image")) {
    const std::unique_ptr<ObjectReader> image =
        floor->Map("image", "'image'", "{file: images/nest.png, min: [x, y], max: [x, y]}");
    if (!image) floor->Fail("image", "'image' must be {file: name.png, min: [x, y], max: [x, y]}");
    image->Expect(std::vector<std::string>{"file", "min", "max"});
    image->Require("file");
    const std::string file = image->String("file", true);
    if (file.empty()) image->Fail("file", "'file' must name a PNG file");
    try {
      ReadFloorImage(context.world_folder / file, &settings);
    } catch (const Error& e) {
      image->Fail("file", e.what());
    }
    if (image->Has("min") || image->Has("max")) {
      Vec3 lo, hi;
      Corners(*image, "'image'", &lo, &hi);
      settings.image_min_x = lo.x, settings.image_min_y = lo.y;
      settings.image_max_x = hi.x, settings.image_max_y = hi.y;
      image_placed = true;
    }
  }
  // The area: given, else the arena's, else the image's corners.
  if (floor->Has("area")) {
    const std::unique_ptr<ObjectReader> area =
        floor->Map("area", "'area'", "{min: [x, y], max: [x, y]}");
    if (!area) floor->Fail("area", "'area' must be {min: [x, y], max: [x, y]}");
    area->Expect(std::vector<std::string>{"min", "max"});
    Vec3 lo, hi;
    Corners(*area, "'area'", &lo, &hi);
    settings.min_x = lo.x, settings.min_y = lo.y, settings.max_x = hi.x, settings.max_y = hi.y;
  } else if (context.arena) {
    settings.min_x = context.arena->min_x, settings.min_y = context.arena->min_y;
    settings.max_x = context.arena->max_x, settings.max_y = context.arena->max_y;
  } else if (image_placed) {
    settings.min_x = settings.image_min_x, settings.min_y = settings.image_min_y;
    settings.max_x = settings.image_max_x, settings.max_y = settings.image_max_y;
  } else {
    floor->FailHere(
        "the floor needs an area: give an 'arena', 'floor: {area: {min: [x, y], max: [x, y]}}' "
        "or the image's corners");
  }
  if (!settings.image_rgb.empty() && !image_placed) {
    settings.image_min_x = settings.min_x, settings.image_min_y = settings.min_y;
    settings.image_max_x = settings.max_x, settings.image_max_y = settings.max_y;
  }
  // The resolution: given, else 1 cm, or the image's pixel size if finer.
  if (floor->Has("resolution")) {
    settings.resolution = floor->Number("resolution", kPositiveLength);
  } else if (!settings.image_rgb.empty()) {
    settings.resolution =
        std::min({0.01, (settings.image_max_x - settings.image_min_x) / settings.image_width,
                  (settings.image_max_y - settings.image_min_y) / settings.image_height});
  }
  for (const std::unique_ptr<ObjectReader>& shape :
       floor->Maps("shapes", "floor shapes", "a floor shape"))
    settings.shapes.push_back(ReadShape(*shape));
  try {
    world->AddModule("floor", &settings);
  } catch (const Error& e) {
    floor->FailHere(e.what());
  }
}

}  // namespace

std::shared_ptr<const WorldSectionDescriptor> FloorSection() {
  auto section = std::make_shared<WorldSectionDescriptor>();
  section->key = "floor";
  section->doc = "the floor ground sensors read: background, PNG image, shapes (nests, zones)";
  section->keys = kKeys;
  section->read = ReadFloor;
  return section;
}

}  // namespace swarmsim::floors
