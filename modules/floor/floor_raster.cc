// The floor drawn into a raster (floor.h): background, image, shapes, once.
#include <algorithm>
#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/floor/floor.h"
#include "modules/paint/png_io.h"

namespace swarmsim::floors {

namespace {

uint8_t ToByte(double c) {
  return static_cast<uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255));
}

Vec3 Mix(const Vec3& a, const Vec3& b, double t) { return a + (b - a) * t; }

// Whether the point (x, y) is inside `s`, and its colour there.
bool ShapeColor(const FloorShape& s, double x, double y, Vec3* color) {
  switch (s.kind) {
    case FloorShape::Kind::kCircle: {
      const double dx = x - s.a.x, dy = y - s.a.y;
      if (dx * dx + dy * dy > s.radius * s.radius) return false;
      *color = s.color;
      return true;
    }
    case FloorShape::Kind::kRectangle:
      if (x < s.a.x || x > s.b.x || y < s.a.y || y > s.b.y) return false;
      *color = s.color;
      return true;
    case FloorShape::Kind::kLinearGradient: {
      if (s.bounded && (x < s.lo.x || x > s.hi.x || y < s.lo.y || y > s.hi.y)) return false;
      const double ux = s.b.x - s.a.x, uy = s.b.y - s.a.y;
      const double t = ((x - s.a.x) * ux + (y - s.a.y) * uy) / (ux * ux + uy * uy);
      *color = Mix(s.color, s.color2, std::clamp(t, 0.0, 1.0));
      return true;
    }
    case FloorShape::Kind::kRadialGradient: {
      const double dx = x - s.a.x, dy = y - s.a.y;
      const double d = std::sqrt(dx * dx + dy * dy);
      if (d > s.radius) return false;
      *color = Mix(s.color, s.color2, s.radius > 0 ? d / s.radius : 0.0);
      return true;
    }
  }
  return false;
}

// The shape's bounding box in the world (everything for an unbounded gradient).
void ShapeBox(const FloorShape& s, double* x0, double* y0, double* x1, double* y1) {
  switch (s.kind) {
    case FloorShape::Kind::kCircle:
    case FloorShape::Kind::kRadialGradient:
      *x0 = s.a.x - s.radius, *y0 = s.a.y - s.radius;
      *x1 = s.a.x + s.radius, *y1 = s.a.y + s.radius;
      return;
    case FloorShape::Kind::kRectangle: *x0 = s.a.x, *y0 = s.a.y, *x1 = s.b.x, *y1 = s.b.y; return;
    case FloorShape::Kind::kLinearGradient:
      if (s.bounded) {
        *x0 = s.lo.x, *y0 = s.lo.y, *x1 = s.hi.x, *y1 = s.hi.y;
      } else {
        *x0 = *y0 = -INFINITY;
        *x1 = *y1 = INFINITY;
      }
      return;
  }
}

}  // namespace

FloorRaster::FloorRaster(World* world, const FloorSettings& settings) : world_(world) {
  const double res = settings.resolution;
  if (!(res > 0) || !std::isfinite(res))
    throw Error("floor: the resolution must be a positive number of metres per pixel");
  const double w = settings.max_x - settings.min_x, h = settings.max_y - settings.min_y;
  if (!(w > 0) || !(h > 0) || !std::isfinite(w) || !std::isfinite(h))
    throw Error("floor: the area must have a positive width and depth");
  const double cols = std::ceil(w / res - 1e-9), rows = std::ceil(h / res - 1e-9);
  if (cols * rows > static_cast<double>(kMaxFloorPixels))
    throw Error("floor: a " + std::to_string(static_cast<int64_t>(cols)) + " x " +
                std::to_string(static_cast<int64_t>(rows)) + " raster is over " +
                std::to_string(kMaxFloorPixels / 1'000'000) +
                " megapixels; use a coarser resolution");
  area_ = {settings.min_x,         settings.min_y,         settings.max_x,     settings.max_y, res,
           static_cast<int>(cols), static_cast<int>(rows), settings.background};
  const size_t n = static_cast<size_t>(area_.width) * static_cast<size_t>(area_.height);
  const uint8_t bg[3] = {ToByte(settings.background.x), ToByte(settings.background.y),
                         ToByte(settings.background.z)};
  rgb_.resize(3 * n);
  for (size_t p = 0; p < n; ++p)
    std::copy(bg, bg + 3, rgb_.begin() + static_cast<ptrdiff_t>(3 * p));
  std::vector<uint8_t> drawn(n, 0);
  const auto centre_x = [&](int c) { return area_.min_x + (c + 0.5) * res; };
  const auto centre_y = [&](int r) { return area_.max_y - (r + 0.5) * res; };
  // The image: each pixel whose centre lies on it takes the image pixel there.
  if (!settings.image_rgb.empty()) {
    const double iw = settings.image_max_x - settings.image_min_x;
    const double ih = settings.image_max_y - settings.image_min_y;
    for (int r = 0; r < area_.height; ++r) {
      const double y = centre_y(r);
      if (y < settings.image_min_y || y >= settings.image_max_y) continue;
      const int ir =
          std::min(settings.image_height - 1,
                   static_cast<int>((settings.image_max_y - y) / ih * settings.image_height));
      for (int c = 0; c < area_.width; ++c) {
        const double x = centre_x(c);
        if (x < settings.image_min_x || x >= settings.image_max_x) continue;
        const int ic =
            std::min(settings.image_width - 1,
                     static_cast<int>((x - settings.image_min_x) / iw * settings.image_width));
        const size_t p = static_cast<size_t>(r) * area_.width + c;
        const uint8_t* src =
            &settings.image_rgb[3 * (static_cast<size_t>(ir) * settings.image_width + ic)];
        std::copy(src, src + 3, rgb_.begin() + static_cast<ptrdiff_t>(3 * p));
        drawn[p] = 1;
      }
    }
  }
  // The shapes in file order, each over what is there; only the pixels in
  // its bounding box are tested.
  for (const FloorShape& s : settings.shapes) {
    double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    ShapeBox(s, &x0, &y0, &x1, &y1);
    const int c0 = static_cast<int>(std::clamp(std::floor((x0 - area_.min_x) / res), 0.0, cols));
    const int c1 =
        static_cast<int>(std::clamp(std::floor((x1 - area_.min_x) / res), -1.0, cols - 1));
    const int r0 = static_cast<int>(std::clamp(std::floor((area_.max_y - y1) / res), 0.0, rows));
    const int r1 =
        static_cast<int>(std::clamp(std::floor((area_.max_y - y0) / res), -1.0, rows - 1));
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c) {
        Vec3 color;
        if (!ShapeColor(s, centre_x(c), centre_y(r), &color)) continue;
        const size_t p = static_cast<size_t>(r) * area_.width + c;
        rgb_[3 * p] = ToByte(color.x);
        rgb_[3 * p + 1] = ToByte(color.y);
        rgb_[3 * p + 2] = ToByte(color.z);
        drawn[p] = 1;
      }
  }
  // Marked: drawn in a colour other than the background's (what the
  // recorder sends; the rest shows the background).
  marked_.assign(n, 0);
  for (size_t p = 0; p < n; ++p)
    marked_[p] = drawn[p] && !std::equal(bg, bg + 3, rgb_.begin() + static_cast<ptrdiff_t>(3 * p));
  world_->set_floor_layer(this);
}

FloorRaster::~FloorRaster() {
  if (world_->floor_layer() == this) world_->set_floor_layer(nullptr);
}

void ReadFloorImage(const std::filesystem::path& path, FloorSettings* settings) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw Error("floor image '" + path.string() + "' not found");
  if (!std::filesystem::is_regular_file(path, ec))
    throw Error("floor image '" + path.string() + "' is not a file");
  paint::RgbImage image;
  try {
    image = paint::ReadPng(path, kMaxFloorPixels);
  } catch (const Error& e) {
    throw Error(std::string("floor image: ") + e.what() + " (a PNG file of at most " +
                std::to_string(kMaxFloorPixels / 1'000'000) + " megapixels is expected)");
  }
  if (image.width <= 0 || image.height <= 0)
    throw Error("floor image '" + path.string() + "' has no pixels");
  settings->image_width = image.width;
  settings->image_height = image.height;
  settings->image_rgb = std::move(image.rgb);
}

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"floor", "floor", "1.0",
        "the floor ground sensors read: a background, a PNG image, shapes (world file key floor:)"},
       0,
       0,
       /*every_world=*/false,
       [](World* world, const void* config) -> std::unique_ptr<Module> {
         if (config == nullptr) throw Error("the floor module needs its settings (floor:)");
         return std::make_unique<FloorRaster>(world, *static_cast<const FloorSettings*>(config));
       },
       nullptr});
}

}  // namespace swarmsim::floors
