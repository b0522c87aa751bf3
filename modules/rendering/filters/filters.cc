// The chain: parsing a sensor's `filters:` list against the registry's
// elements (kinds checked at each item), and running it on an image.
#include "modules/rendering/filters/filters.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "modules/rendering/filters/element.h"

namespace swarmsim::filters {

struct ChainData {
  std::vector<std::shared_ptr<const VisionFilterElement>> elements;
  bool needs_depth = false;
};

namespace {

// --- Kinds in messages ----------------------------------------------------------------

std::string KindText(uint32_t kind) {
  switch (kind) {
    case kSwarmsimColourImage: return "a colour image";
    case kSwarmsimGreyImage: return "a grey image";
    case kSwarmsimMask: return "a mask";
    case kSwarmsimDepthImage: return "a depth image";
    case kSwarmsimValues: return "values (no image)";
  }
  return "?";
}

// "a colour image or a grey image".
std::string KindsText(uint32_t kinds) {
  std::string out;
  for (uint32_t bit = 1; bit <= kSwarmsimValues; bit <<= 1)
    if (kinds & bit) out += (out.empty() ? "" : " or ") + KindText(bit);
  return out;
}

// What to put before an element that needs `kinds`.
std::string Hint(uint32_t kinds) {
  if (kinds & kSwarmsimMask)
    return "put a threshold before it (hsv_threshold, color_threshold, depth_threshold or edges)";
  if (kinds & kSwarmsimColourImage) return "put 'original' (the camera's image) before it";
  if (kinds & kSwarmsimGreyImage) return "put 'grayscale' before it";
  if (kinds & kSwarmsimDepthImage) return "put 'depth' (the camera's depth image) before it";
  return "put another element before it";
}

// --- A plugin's element ---------------------------------------------------------------

class PluginElement final : public VisionFilterElement {
 public:
  PluginElement(std::shared_ptr<const VisionFilterDescriptor> descriptor,
                std::vector<double> parameters)
      : descriptor_(std::move(descriptor)), parameters_(std::move(parameters)) {}

  void Apply(FilterRun* run) const override {
    const VisionFilterDescriptor& d = *descriptor_;
    WorkImage& in = run->work;
    const uint32_t kind = d.output != 0 ? d.output : in.kind;
    const auto view = [](WorkImage& image) {
      const bool depth = image.kind == kSwarmsimDepthImage;
      return SwarmsimImage{image.width, image.height, static_cast<int>(image.kind),
                           depth ? nullptr : image.pixels.data(),
                           depth ? image.depth.data() : nullptr};
    };
    const SwarmsimImage input = view(in);
    SwarmsimImage output{in.width, in.height, static_cast<int>(kind), nullptr, nullptr};
    if (kind != kSwarmsimValues) {
      run->next.Reset(in.width, in.height, kind);
      output = view(run->next);
    }
    std::vector<double>* packet = nullptr;
    if (d.plugin_max_values > 0) {
      packet = &run->NewPacket();
      packet->resize(static_cast<size_t>(d.plugin_max_values));
    }
    char error[256] = "";
    const int n =
        d.plugin_function(&input, &output, parameters_.data(), packet ? packet->data() : nullptr,
                          d.plugin_max_values, error, sizeof error, d.plugin_user_data);
    error[sizeof error - 1] = '\0';
    if (n < 0) throw Error("vision filter '" + d.name + "': " + (error[0] ? error : "failed"));
    if (packet) packet->resize(static_cast<size_t>(std::min(n, d.plugin_max_values)));
    if (kind != kSwarmsimValues) run->Swap();
  }

 private:
  std::shared_ptr<const VisionFilterDescriptor> descriptor_;  // keeps the function's plugin info
  std::vector<double> parameters_;
};

std::shared_ptr<const VisionFilterElement> MakePluginElement(
    std::shared_ptr<const VisionFilterDescriptor> d, const ObjectReader& item) {
  std::vector<double> parameters;
  for (const VisionFilterKey& key : d->keys) {
    parameters.push_back(key.default_value);
    if (!item.Has(key.name)) continue;
    char text[96];
    std::snprintf(text, sizeof text, "a number from %g to %g", key.min, key.max);
    parameters.back() = item.Number(key.name, {text, key.min, key.max});
  }
  return std::make_shared<const PluginElement>(std::move(d), std::move(parameters));
}

// --- Running --------------------------------------------------------------------------

// Packet 1 (CoppeliaSim's): min, max and mean of intensity, red, green,
// blue and depth (0..1; depth from the near plane to the far one, 1 without
// a depth image: nothing seen), in that order.
void Statistics(const Image& image, const CameraModel& camera, std::vector<double>* packet) {
  const size_t n = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  const uint8_t* rgb = image.rgb.data();
  // Channels over blocks of 16 pixels (48 bytes; lane j holds channel j % 3),
  // which the compiler vectorises; then the rest pixel by pixel.
  constexpr size_t kLanes = 48;
  uint8_t lo[kLanes], hi[kLanes];
  uint32_t total[kLanes];
  std::fill(lo, lo + kLanes, uint8_t{255});
  std::fill(hi, hi + kLanes, uint8_t{0});
  std::fill(total, total + kLanes, 0u);
  const size_t blocked = n * 3 / kLanes * kLanes;
  for (size_t i = 0; i < blocked; i += kLanes)
    for (size_t j = 0; j < kLanes; ++j) {
      const uint8_t v = rgb[i + j];
      lo[j] = std::min(lo[j], v);
      hi[j] = std::max(hi[j], v);
      total[j] += v;
    }
  for (size_t i = blocked; i < n * 3; ++i) {
    const size_t j = i % 3;  // blocked is a multiple of 3
    lo[j] = std::min(lo[j], rgb[i]);
    hi[j] = std::max(hi[j], rgb[i]);
    total[j] += rgb[i];
  }
  int min[4] = {765, 255, 255, 255}, max[4] = {0, 0, 0, 0};
  int64_t sum[4] = {0, 0, 0, 0};
  for (size_t j = 0; j < kLanes; ++j) {
    const size_t c = 1 + j % 3;
    min[c] = std::min<int>(min[c], lo[j]);
    max[c] = std::max<int>(max[c], hi[j]);
    sum[c] += total[j];
  }
  sum[0] = sum[1] + sum[2] + sum[3];
  // Intensity extremes need each pixel's sum: four pixels a turn, each in
  // its own chain.
  int i_lo[4] = {765, 765, 765, 765}, i_hi[4] = {0, 0, 0, 0};
  const size_t quads = n / 4 * 4;
  for (size_t i = 0; i < quads; i += 4)
    for (size_t k = 0; k < 4; ++k) {
      const uint8_t* c = rgb + 3 * (i + k);
      const int s = c[0] + c[1] + c[2];
      i_lo[k] = std::min(i_lo[k], s);
      i_hi[k] = std::max(i_hi[k], s);
    }
  for (size_t i = quads; i < n; ++i) {
    const int s = rgb[3 * i] + rgb[3 * i + 1] + rgb[3 * i + 2];
    i_lo[0] = std::min(i_lo[0], s);
    i_hi[0] = std::max(i_hi[0], s);
  }
  min[0] = *std::min_element(i_lo, i_lo + 4);
  max[0] = *std::max_element(i_hi, i_hi + 4);
  const double no_depth = n > 0 ? 1.0 : 0.0;
  double depth_min = no_depth, depth_max = no_depth, depth_mean = no_depth;
  if (n > 0 && image.depth.size() == n) {
    // Loops the compiler vectorises. Depths are >= 0, so their bit patterns
    // order as the numbers do: an integer min and max.
    const float* d = image.depth.data();
    int32_t bits_lo, bits_hi;
    std::memcpy(&bits_lo, d, 4);
    bits_hi = bits_lo;
    for (size_t i = 0; i < n; ++i) {
      int32_t bits;
      std::memcpy(&bits, d + i, 4);
      bits_lo = std::min(bits_lo, bits);
      bits_hi = std::max(bits_hi, bits);
    }
    // The sum in eight float lanes (each sums at most n / 8 depths).
    constexpr size_t kLanes8 = 8;
    float d_total[kLanes8] = {};
    const size_t chained = n / kLanes8 * kLanes8;
    for (size_t i = 0; i < chained; i += kLanes8)
      for (size_t j = 0; j < kLanes8; ++j) d_total[j] += d[i + j];
    for (size_t i = chained; i < n; ++i) d_total[0] += d[i];
    const auto as_float = [](int32_t bits) {
      float f;
      std::memcpy(&f, &bits, 4);
      return f;
    };
    const double range = camera.far > camera.near ? camera.far - camera.near : 1;
    const auto normalise = [&](double v) {
      return std::clamp((v - camera.near) / range, 0.0, 1.0);
    };
    depth_min = normalise(as_float(bits_lo));
    depth_max = normalise(as_float(bits_hi));
    double all = 0;
    for (float t : d_total) all += t;
    depth_mean = normalise(all / static_cast<double>(n));
  }
  const double scale[4] = {765, 255, 255, 255};
  const double count = n > 0 ? static_cast<double>(n) : 1;
  packet->clear();
  for (int k = 0; k < 4; ++k) packet->push_back(n > 0 ? min[k] / scale[k] : 0);
  packet->push_back(depth_min);
  for (int k = 0; k < 4; ++k) packet->push_back(n > 0 ? max[k] / scale[k] : 0);
  packet->push_back(depth_max);
  for (int k = 0; k < 4; ++k) packet->push_back(static_cast<double>(sum[k]) / scale[k] / count);
  packet->push_back(depth_mean);
}

// The work image as RGB: grey levels for grey and masks, depth from black
// at the near plane to white at the far one.
void ToRgb(const WorkImage& work, const CameraModel& camera, Image* out) {
  out->width = work.width;
  out->height = work.height;
  out->depth.clear();
  const size_t n = work.count();
  out->rgb.resize(n * 3);
  uint8_t* o = out->rgb.data();
  if (work.kind == kSwarmsimColourImage) {
    if (n > 0) std::memcpy(o, work.pixels.data(), n * 3);
  } else if (work.kind == kSwarmsimDepthImage) {
    const double range = camera.far > camera.near ? camera.far - camera.near : 1;
    for (size_t i = 0; i < n; ++i, o += 3) {
      const double t = std::clamp((work.depth[i] - camera.near) / range, 0.0, 1.0);
      o[0] = o[1] = o[2] = static_cast<uint8_t>(t * 255 + 0.5);
    }
  } else {
    // Four grey pixels into 12 bytes at a time.
    const uint8_t* g = work.pixels.data();
    size_t i = 0;
    for (; i + 4 <= n; i += 4, o += 12) {
      // Built in registers, stored in two moves (little-endian byte order).
      const uint64_t a = g[i], b = g[i + 1], c = g[i + 2], d = g[i + 3];
      const uint64_t first = a * 0x010101 | b * 0x010101 << 24 | c * 0x0101 << 48;
      const uint32_t last = static_cast<uint32_t>(c | d * 0x010101 << 8);
      std::memcpy(o, &first, 8);
      std::memcpy(o + 8, &last, 4);
    }
    for (; i < n; ++i, o += 3) o[0] = o[1] = o[2] = g[i];
  }
}

const ModuleRegistry& BuiltinRegistry() {
  static const ModuleRegistry registry = [] {
    ModuleRegistry r;
    Register(&r);
    return r;
  }();
  return registry;
}

}  // namespace

FilterChain::FilterChain() : data_(std::make_shared<const ChainData>()) {}

size_t FilterChain::size() const { return data_->elements.size(); }

bool FilterChain::needs_depth() const { return data_->needs_depth; }

FilterOutput FilterChain::Run(const Image& image, const CameraModel& camera) const {
  FilterOutput out;
  Run(image, camera, &out);
  return out;
}

void FilterChain::Run(const Image& image, const CameraModel& camera, FilterOutput* out,
                      bool statistics) const {
  SWARMSIM_CHECK(image.width >= 0 && image.height >= 0 &&
                     image.rgb.size() ==
                         static_cast<size_t>(image.width) * static_cast<size_t>(image.height) * 3,
                 "a filter chain's image has " + std::to_string(image.rgb.size()) + " bytes for " +
                     std::to_string(image.width) + "x" + std::to_string(image.height) + " pixels");
  if (out->packets.empty()) out->packets.emplace_back();
  if (statistics) {
    Statistics(image, camera, &out->packets[0]);
  } else {
    out->packets[0].clear();
  }
  out->blobs.clear();
  out->points.clear();
  out->triggered = false;
  FilterRun run;
  run.source = &image;
  run.camera = &camera;
  run.out = out;
  run.work.Reset(image.width, image.height, kSwarmsimColourImage);
  if (!image.rgb.empty())  // (an empty image's data() may be null)
    std::memcpy(run.work.pixels.data(), image.rgb.data(), image.rgb.size());
  // An empty image has nothing to filter (a sensor refuses resolution 0).
  if (image.width > 0 && image.height > 0)
    for (const auto& element : data_->elements) element->Apply(&run);
  out->packets.resize(run.packets);
  ToRgb(run.work, camera, &out->image);
}

std::vector<double> ImageStatistics(const Image& image, const CameraModel& camera) {
  std::vector<double> packet;
  Statistics(image, camera, &packet);
  return packet;
}

Vec3 ImageToSensor(const CameraModel& camera, int width, int height, double x, double y,
                   double depth) {
  return Projection(camera, width, height).Point(x, y, depth);
}

FilterChain ParseFilterChain(const ObjectReader& reader, std::string_view key,
                             const ModuleRegistry* registry) {
  // A registry without elements (a test's, a tool's) gets the built-in ones.
  const ModuleRegistry& elements =
      registry != nullptr && !registry->vision_filters().empty() ? *registry : BuiltinRegistry();
  std::vector<std::string> names, all_keys = {"type"};
  for (const auto& d : elements.vision_filters()) {
    names.push_back(d->name);
    for (const VisionFilterKey& k : d->keys)
      if (std::find(all_keys.begin(), all_keys.end(), k.name) == all_keys.end())
        all_keys.push_back(k.name);
  }
  auto data = std::make_shared<ChainData>();
  uint32_t kind = kSwarmsimColourImage;
  std::string before = "the camera gives";
  for (const std::unique_ptr<ObjectReader>& item : reader.Items(key)) {
    // A misspelt 'type' is an unknown key (with a suggestion), not a missing one.
    if (!item->Has("type")) item->Expect(all_keys);
    const std::string name = item->Choice("type", names, /*required=*/true);
    std::shared_ptr<const VisionFilterDescriptor> d;
    for (const auto& e : elements.vision_filters())
      if (e->name == name) d = e;
    std::vector<std::string> known = {"type"};
    for (const VisionFilterKey& k : d->keys) known.push_back(k.name);
    item->Expect(known);
    if ((d->input & kind) == 0)
      item->Fail("type", "'" + name + "' needs " + KindsText(d->input) + "; " + before + " " +
                             KindText(kind) + ": " + Hint(d->input));
    data->elements.push_back(d->make ? d->make(*item) : MakePluginElement(d, *item));
    const uint32_t output = d->output != 0 ? d->output : kind;
    if (output == kSwarmsimDepthImage) data->needs_depth = true;
    kind = output;
    before = "'" + name + "' gives";
  }
  FilterChain chain;
  chain.data_ = std::move(data);
  return chain;
}

}  // namespace swarmsim::filters
