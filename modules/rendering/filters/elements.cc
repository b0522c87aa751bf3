// The built-in filter elements and their registration. Each is a small
// immutable class: its settings, read once from its list item, and Apply.
// Per-pixel loops are plain loops over bytes (no per-pixel calls through
// pointers, no allocation per pixel).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "modules/rendering/filters/element.h"

namespace swarmsim::filters {
namespace {

constexpr uint32_t kColour = kSwarmsimColourImage, kGrey = kSwarmsimGreyImage,
                   kMask = kSwarmsimMask, kDepth = kSwarmsimDepthImage, kValues = kSwarmsimValues;
constexpr uint32_t kAnyImage = kColour | kGrey | kMask | kDepth;
constexpr uint32_t kAnything = kAnyImage | kValues;

constexpr NumberRule kDepthRule{"a non-negative number of metres", 0, 1e9};

// --- grayscale ------------------------------------------------------------------------

class Grayscale final : public VisionFilterElement {
 public:
  void Apply(FilterRun* run) const override {
    const WorkImage& in = run->work;
    run->next.Reset(in.width, in.height, kGrey);
    const uint8_t* c = in.pixels.data();
    uint8_t* g = run->next.pixels.data();
    for (size_t i = 0, n = in.count(); i < n; ++i, c += 3) g[i] = Intensity(c);
    run->Swap();
  }
};

// --- resize ---------------------------------------------------------------------------

// ceil(p / q) for q > 0 and any p.
int64_t CeilDiv(int64_t p, int64_t q) { return p >= 0 ? (p + q - 1) / q : -((-p) / q); }

// For each output index 0..out-1 of a side of `in` pixels: the source pixels
// whose centres fall inside its cell, or (enlarging) the nearest one.
std::vector<std::pair<int, int>> Cells(int in, int out) {
  std::vector<std::pair<int, int>> cells(static_cast<size_t>(out));
  for (int i = 0; i < out; ++i) {
    const int64_t first = CeilDiv(2LL * i * in - out, 2LL * out);
    const int64_t last = CeilDiv(2LL * (i + 1) * in - out, 2LL * out) - 1;
    if (last < first) {
      const int nearest = static_cast<int>((2LL * i + 1) * in / (2LL * out));
      cells[static_cast<size_t>(i)] = {nearest, nearest};
    } else {
      cells[static_cast<size_t>(i)] = {static_cast<int>(first), static_cast<int>(last)};
    }
  }
  return cells;
}

class Resize final : public VisionFilterElement {
 public:
  Resize(int width, int height) : width_(width), height_(height) {}
  // Each output pixel is the mean of the source pixels in its cell (a mask
  // stays a mask: set where at least half are set).
  void Apply(FilterRun* run) const override {
    const WorkImage& in = run->work;
    WorkImage& out = run->next;
    out.Reset(width_, height_, in.kind);
    const auto columns = Cells(in.width, width_), rows = Cells(in.height, height_);
    const int channels = in.kind == kColour ? 3 : 1;
    for (int y = 0; y < height_; ++y) {
      const auto [y0, y1] = rows[static_cast<size_t>(y)];
      for (int x = 0; x < width_; ++x) {
        const auto [x0, x1] = columns[static_cast<size_t>(x)];
        const int n = (y1 - y0 + 1) * (x1 - x0 + 1);
        const size_t o = static_cast<size_t>(y) * width_ + x;
        if (in.kind == kDepth) {
          double sum = 0;
          for (int sy = y0; sy <= y1; ++sy)
            for (int sx = x0; sx <= x1; ++sx)
              sum += in.depth[static_cast<size_t>(sy) * in.width + sx];
          out.depth[o] = static_cast<float>(sum / n);
          continue;
        }
        for (int c = 0; c < channels; ++c) {
          int sum = 0;
          for (int sy = y0; sy <= y1; ++sy)
            for (int sx = x0; sx <= x1; ++sx)
              sum += in.pixels[(static_cast<size_t>(sy) * in.width + sx) * channels + c];
          out.pixels[o * channels + c] = in.kind == kMask ? (2 * sum >= 255 * n ? 255 : 0)
                                                          : static_cast<uint8_t>((sum + n / 2) / n);
        }
      }
    }
    run->Swap();
  }

 private:
  int width_, height_;
};

// --- color_threshold ------------------------------------------------------------------

class ColorThreshold final : public VisionFilterElement {
 public:
  ColorThreshold(const std::vector<double>& colour, double tolerance) {
    for (int c = 0; c < 3; ++c) {
      lo_[c] = static_cast<int>(std::ceil(255 * (colour[c] - tolerance) - 1e-9));
      hi_[c] = static_cast<int>(std::floor(255 * (colour[c] + tolerance) + 1e-9));
    }
  }
  void Apply(FilterRun* run) const override {
    const WorkImage& in = run->work;
    run->next.Reset(in.width, in.height, kMask);
    const uint8_t* c = in.pixels.data();
    uint8_t* m = run->next.pixels.data();
    const int lo0 = lo_[0], lo1 = lo_[1], lo2 = lo_[2], hi0 = hi_[0], hi1 = hi_[1], hi2 = hi_[2];
    for (size_t i = 0, n = in.count(); i < n; ++i, c += 3) {
      const bool in_range =
          c[0] >= lo0 && c[0] <= hi0 && c[1] >= lo1 && c[1] <= hi1 && c[2] >= lo2 && c[2] <= hi2;
      m[i] = in_range ? 255 : 0;
    }
    run->Swap();
  }

 private:
  int lo_[3], hi_[3];
};

// --- hsv_threshold --------------------------------------------------------------------

class HsvThreshold final : public VisionFilterElement {
 public:
  // Per largest channel (the value, 0..255): the range of max - min a kept
  // pixel may have, which folds the value range and the saturation range
  // ((max - min) / max, exact to 1/65536) into one table.
  HsvThreshold(const std::vector<double>& hue, const std::vector<double>& saturation,
               const std::vector<double>& value)
      : hue_lo_(static_cast<float>(hue[0])), hue_hi_(static_cast<float>(hue[1])) {
    constexpr int64_t kOne = 1 << 16;  // saturation 1
    const int64_t saturation_lo = static_cast<int64_t>(std::ceil(saturation[0] * kOne - 1e-9));
    const int64_t saturation_hi = static_cast<int64_t>(std::floor(saturation[1] * kOne + 1e-9));
    const int value_lo = static_cast<int>(std::ceil(255 * value[0] - 1e-9));
    const int value_hi = static_cast<int>(std::floor(255 * value[1] + 1e-9));
    for (int max = 0; max < 256; ++max) {
      Range& range = delta_[max];
      range = {1, 0};  // empty
      if (max < value_lo || max > value_hi) continue;
      for (int delta = 0; delta <= max; ++delta) {
        // delta / max against the range, without a division; black (max 0)
        // has saturation 0.
        const int64_t scaled = max > 0 ? delta * kOne : 0, bound = max > 0 ? max : 1;
        if (scaled < saturation_lo * bound || scaled > saturation_hi * bound) continue;
        if (range.lo > range.hi) range.lo = static_cast<int16_t>(delta);
        range.hi = static_cast<int16_t>(delta);
      }
    }
  }

  // The table first; the hue (degrees, 0 for grey) only for what it keeps.
  void Apply(FilterRun* run) const override {
    const WorkImage& in = run->work;
    run->next.Reset(in.width, in.height, kMask);
    const uint8_t* c = in.pixels.data();
    uint8_t* m = run->next.pixels.data();
    // Locals, not members: the stores into the mask would make the
    // compiler reload members every pixel.
    const float hue_lo = hue_lo_, hue_hi = hue_hi_;
    const bool wraps = hue_lo > hue_hi;
    const Range* table = delta_;
    for (size_t i = 0, n = in.count(); i < n; ++i, c += 3) {
      const int r = c[0], g = c[1], b = c[2];
      const int max = std::max(r, std::max(g, b)), min = std::min(r, std::min(g, b));
      const int delta = max - min;
      const Range range = table[max];
      m[i] = 0;
      if (delta < range.lo || delta > range.hi) continue;
      float h = 0;
      if (delta > 0) {
        const float fdelta = static_cast<float>(delta);
        if (max == r) {
          h = 60.0f * static_cast<float>(g - b) / fdelta;
          if (h < 0) h += 360.0f;
        } else if (max == g) {
          h = 120.0f + 60.0f * static_cast<float>(b - r) / fdelta;
        } else {
          h = 240.0f + 60.0f * static_cast<float>(r - g) / fdelta;
        }
      }
      const bool hue_ok = wraps ? (h >= hue_lo || h <= hue_hi) : (h >= hue_lo && h <= hue_hi);
      if (hue_ok) m[i] = 255;
    }
    run->Swap();
  }

 private:
  struct Range {
    int16_t lo, hi;  // max - min kept, inclusive (lo > hi: none)
  };
  float hue_lo_, hue_hi_;
  Range delta_[256];  // by the largest channel (1 KiB, shared by the chain's copies)
};

// --- edges ----------------------------------------------------------------------------

class Edges final : public VisionFilterElement {
 public:
  explicit Edges(double threshold) {
    // |gradient| of a black-to-white step is 4 * 255: threshold 1 is that.
    const double t = threshold * 4 * 255;
    threshold_squared_ = static_cast<int64_t>(std::ceil(t * t - 1e-6));
  }
  // Sobel on the intensity, borders extended.
  void Apply(FilterRun* run) const override {
    const WorkImage& in = run->work;
    const int w = in.width, h = in.height;
    std::vector<uint8_t> grey_store;
    const uint8_t* grey = in.pixels.data();
    if (in.kind == kColour) {
      grey_store.resize(in.count());
      const uint8_t* c = in.pixels.data();
      for (size_t i = 0; i < grey_store.size(); ++i, c += 3) grey_store[i] = Intensity(c);
      grey = grey_store.data();
    }
    run->next.Reset(w, h, kMask);
    uint8_t* m = run->next.pixels.data();
    for (int y = 0; y < h; ++y) {
      const uint8_t* up = grey + static_cast<size_t>(std::max(y - 1, 0)) * w;
      const uint8_t* mid = grey + static_cast<size_t>(y) * w;
      const uint8_t* down = grey + static_cast<size_t>(std::min(y + 1, h - 1)) * w;
      for (int x = 0; x < w; ++x) {
        const int l = std::max(x - 1, 0), r = std::min(x + 1, w - 1);
        const int gx = (up[r] + 2 * mid[r] + down[r]) - (up[l] + 2 * mid[l] + down[l]);
        const int gy = (down[l] + 2 * down[x] + down[r]) - (up[l] + 2 * up[x] + up[r]);
        const int64_t squared = static_cast<int64_t>(gx) * gx + static_cast<int64_t>(gy) * gy;
        m[static_cast<size_t>(y) * w + x] = squared >= threshold_squared_ && squared > 0 ? 255 : 0;
      }
    }
    run->Swap();
  }

 private:
  int64_t threshold_squared_;
};

// --- blobs ----------------------------------------------------------------------------

class Blobs final : public VisionFilterElement {
 public:
  Blobs(int min_pixels, int max_blobs) : min_pixels_(min_pixels), max_blobs_(max_blobs) {}
  void Apply(FilterRun* run) const override { DetectBlobs(run, min_pixels_, max_blobs_); }

 private:
  int min_pixels_, max_blobs_;
};

// --- original, depth ------------------------------------------------------------------

class Original final : public VisionFilterElement {
 public:
  void Apply(FilterRun* run) const override {
    const Image& s = *run->source;
    run->next.Reset(s.width, s.height, kColour);
    std::memcpy(run->next.pixels.data(), s.rgb.data(), run->next.pixels.size());
    run->Swap();
  }
};

// The camera's depth image; without one, every pixel at the far plane.
class Depth final : public VisionFilterElement {
 public:
  void Apply(FilterRun* run) const override {
    const Image& s = *run->source;
    run->next.Reset(s.width, s.height, kDepth);
    if (s.depth.size() == run->next.depth.size()) {
      std::copy(s.depth.begin(), s.depth.end(), run->next.depth.begin());
    } else {
      std::fill(run->next.depth.begin(), run->next.depth.end(),
                static_cast<float>(run->camera->far));
    }
    run->Swap();
  }
};

class DepthThreshold final : public VisionFilterElement {
 public:
  DepthThreshold(double min, double max)
      : min_(static_cast<float>(min)), max_(static_cast<float>(max)) {}
  void Apply(FilterRun* run) const override {
    const WorkImage& in = run->work;
    run->next.Reset(in.width, in.height, kMask);
    uint8_t* m = run->next.pixels.data();
    for (size_t i = 0, n = in.count(); i < n; ++i)
      m[i] = in.depth[i] >= min_ && in.depth[i] <= max_ ? 255 : 0;
    run->Swap();
  }

 private:
  float min_, max_;
};

// --- point_cloud ----------------------------------------------------------------------

// A point per pixel at depth d, in the sensor's frame (Projection).
// Pixels at the far plane (nothing seen) give no point.
class PointCloud final : public VisionFilterElement {
 public:
  explicit PointCloud(int stride) : stride_(stride) {}
  void Apply(FilterRun* run) const override {
    const WorkImage& in = run->work;
    const Projection projection(*run->camera, in.width, in.height);
    const float far = static_cast<float>(run->camera->far * (1 - 1e-6));
    std::vector<Vec3>& points = run->out->points;
    points.clear();
    for (int y = 0; y < in.height; y += stride_) {
      for (int x = 0; x < in.width; x += stride_) {
        const double d = in.depth[static_cast<size_t>(y) * in.width + x];
        if (!(d > 0) || d >= far) continue;
        points.push_back(projection.Point(x + 0.5, y + 0.5, d));
      }
    }
    std::vector<double>& packet = run->NewPacket();
    packet.resize(1 + 3 * points.size());
    packet[0] = static_cast<double>(points.size());
    double* v = packet.data() + 1;
    for (const Vec3& p : points) v[0] = p.x, v[1] = p.y, v[2] = p.z, v += 3;
    if (!points.empty()) run->out->triggered = true;
  }

 private:
  int stride_;
};

// --- Descriptors ----------------------------------------------------------------------

std::vector<double> Range(const ObjectReader& r, const char* key, const NumberRule& rule,
                          std::vector<double> fallback, bool wraps) {
  if (!r.Has(key)) return fallback;
  std::vector<double> range = r.Numbers(key, 2, 2, rule);
  if (!wraps && range[0] > range[1])
    r.Fail(key, std::string("'") + key + "' must be [min, max] with min <= max");
  return range;
}

std::shared_ptr<VisionFilterDescriptor> Descriptor(
    const char* name, const char* description, uint32_t input, uint32_t output,
    std::vector<VisionFilterKey> keys,
    std::function<std::shared_ptr<const VisionFilterElement>(const ObjectReader&)> make) {
  auto d = std::make_shared<VisionFilterDescriptor>();
  d->name = name;
  d->description = description;
  d->input = input;
  d->output = output;
  d->keys = std::move(keys);
  d->make = std::move(make);
  return d;
}

std::vector<std::shared_ptr<VisionFilterDescriptor>> BuiltinElements() {
  std::vector<std::shared_ptr<VisionFilterDescriptor>> out;
  out.push_back(
      Descriptor("grayscale", "colour image to grey (the mean of R, G, B)", kColour, kGrey, {},
                 [](const ObjectReader&) { return std::make_shared<const Grayscale>(); }));
  out.push_back(Descriptor(
      "resize", "image of another resolution (cell means; a mask stays a mask)", kAnyImage, 0,
      {{"width", "required", "pixels, 1..4096"}, {"height", "required", "pixels, 1..4096"}},
      [](const ObjectReader& r) {
        if (!r.Has("width") || !r.Has("height"))
          r.Fail("type", "'resize' needs 'width' and 'height' (pixels)");
        return std::make_shared<const Resize>(static_cast<int>(r.Integer("width", 1, 4096)),
                                              static_cast<int>(r.Integer("height", 1, 4096)));
      }));
  out.push_back(Descriptor("color_threshold", "mask of the pixels near one colour", kColour, kMask,
                           {{"color", "required", "RGB, each 0..1: the colour to keep"},
                            {"tolerance", "0.1", "0..1: largest difference in each channel"}},
                           [](const ObjectReader& r) {
                             if (!r.Has("color"))
                               r.Fail("type", "'color_threshold' needs 'color: [r, g, b]'");
                             const std::vector<double> colour = r.Numbers("color", 3, 3, kFraction);
                             const double tolerance =
                                 r.Has("tolerance") ? r.Number("tolerance", kFraction) : 0.1;
                             return std::make_shared<const ColorThreshold>(colour, tolerance);
                           }));
  out.push_back(Descriptor(
      "hsv_threshold", "mask of the pixels within hue, saturation and value ranges", kColour, kMask,
      {{"hue", "[0, 360]", "degrees [min, max]; min > max wraps through 0 (red: [340, 20])"},
       {"saturation", "[0, 1]", "[min, max], each 0..1"},
       {"value", "[0, 1]", "[min, max], each 0..1 (the largest channel)"}},
      [](const ObjectReader& r) {
        constexpr NumberRule kHue{"an angle from 0 to 360 degrees", 0, 360};
        return std::make_shared<const HsvThreshold>(
            Range(r, "hue", kHue, {0, 360}, true), Range(r, "saturation", kFraction, {0, 1}, false),
            Range(r, "value", kFraction, {0, 1}, false));
      }));
  out.push_back(Descriptor(
      "edges", "mask of the edges (Sobel on the intensity)", kColour | kGrey, kMask,
      {{"threshold", "0.2", "0..1: least gradient kept, 1 = a black-to-white step"}},
      [](const ObjectReader& r) {
        return std::make_shared<const Edges>(r.Has("threshold") ? r.Number("threshold", kFraction)
                                                                : 0.2);
      }));
  out.push_back(Descriptor(
      "blobs", "connected parts of a mask: count, size, colour, centroid, box, orientation", kMask,
      kValues,
      {{"min_pixels", "1", "smallest blob kept, pixels"},
       {"max_blobs", "64", "most blobs kept (the largest), 1..4096"}},
      [](const ObjectReader& r) {
        const int min_pixels =
            r.Has("min_pixels") ? static_cast<int>(r.Integer("min_pixels", 1, 1 << 24)) : 1;
        const int max_blobs =
            r.Has("max_blobs") ? static_cast<int>(r.Integer("max_blobs", 1, 4096)) : 64;
        return std::make_shared<const Blobs>(min_pixels, max_blobs);
      }));
  out.push_back(Descriptor("original", "the camera's colour image again", kAnything, kColour, {},
                           [](const ObjectReader&) { return std::make_shared<const Original>(); }));
  out.push_back(Descriptor("depth", "the camera's depth image", kAnything, kDepth, {},
                           [](const ObjectReader&) { return std::make_shared<const Depth>(); }));
  out.push_back(
      Descriptor("depth_threshold", "mask of the pixels within a depth range", kDepth, kMask,
                 {{"range", "required", "m [min, max]: depths kept"}}, [](const ObjectReader& r) {
                   if (!r.Has("range"))
                     r.Fail("type", "'depth_threshold' needs 'range: [min, max]' (m)");
                   const std::vector<double> range = Range(r, "range", kDepthRule, {}, false);
                   return std::make_shared<const DepthThreshold>(range[0], range[1]);
                 }));
  out.push_back(Descriptor(
      "point_cloud", "3D points of the depth image in the sensor's frame", kDepth, kValues,
      {{"stride", "1", "every stride-th pixel in x and y, 1..64"}}, [](const ObjectReader& r) {
        return std::make_shared<const PointCloud>(
            r.Has("stride") ? static_cast<int>(r.Integer("stride", 1, 64)) : 1);
      }));
  return out;
}

}  // namespace

void Register(ModuleRegistry* registry) {
  for (std::shared_ptr<VisionFilterDescriptor>& d : BuiltinElements())
    registry->RegisterVisionFilter(std::move(d));
}

}  // namespace swarmsim::filters
