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
      packet = &run->out->packets.emplace_back();
      packet->resize(static_cast<size_t>(d.plugin_max_values));
    }
    char error[256] = "";
    const int n =
        d.plugin_function(&input, &output, parameters_.data(), packet ? packet->data() : nullptr,
                          d.plugin_max_values, error, sizeof error, d.plugin_user_data);
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
// blue and depth (0..1; depth from the near plane to the far one, 0 without
// a depth image), in that order.
void Statistics(const Image& image, const CameraModel& camera, std::vector<double>* packet) {
  int min[4] = {765, 255, 255, 255}, max[4] = {0, 0, 0, 0};
  int64_t sum[4] = {0, 0, 0, 0};
  const size_t n = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  const uint8_t* c = image.rgb.data();
  for (size_t i = 0; i < n; ++i, c += 3) {
    const int v[4] = {c[0] + c[1] + c[2], c[0], c[1], c[2]};
    for (int k = 0; k < 4; ++k) {
      min[k] = std::min(min[k], v[k]);
      max[k] = std::max(max[k], v[k]);
      sum[k] += v[k];
    }
  }
  double depth_min = 0, depth_max = 0, depth_mean = 0;
  if (n > 0 && image.depth.size() == n) {
    const double range = camera.far > camera.near ? camera.far - camera.near : 1;
    float lo = image.depth[0], hi = image.depth[0];
    double total = 0;
    for (float d : image.depth) {
      lo = std::min(lo, d);
      hi = std::max(hi, d);
      total += d;
    }
    const auto normalise = [&](double d) {
      return std::clamp((d - camera.near) / range, 0.0, 1.0);
    };
    depth_min = normalise(lo);
    depth_max = normalise(hi);
    depth_mean = normalise(total / static_cast<double>(n));
  }
  const double scale[4] = {765, 255, 255, 255};
  const double count = n > 0 ? static_cast<double>(n) : 1;
  packet->clear();
  for (int k = 0; k < 4; ++k) packet->push_back(n > 0 ? min[k] / scale[k] : 0);
  packet->push_back(depth_min);
  for (int k = 0; k < 4; ++k) packet->push_back(max[k] / scale[k]);
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
    std::memcpy(o, work.pixels.data(), n * 3);
  } else if (work.kind == kSwarmsimDepthImage) {
    const double range = camera.far > camera.near ? camera.far - camera.near : 1;
    for (size_t i = 0; i < n; ++i, o += 3) {
      const double t = std::clamp((work.depth[i] - camera.near) / range, 0.0, 1.0);
      o[0] = o[1] = o[2] = static_cast<uint8_t>(t * 255 + 0.5);
    }
  } else {
    for (size_t i = 0; i < n; ++i, o += 3) o[0] = o[1] = o[2] = work.pixels[i];
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

void FilterChain::Run(const Image& image, const CameraModel& camera, FilterOutput* out) const {
  out->packets.resize(1);
  Statistics(image, camera, &out->packets[0]);
  out->blobs.clear();
  out->points.clear();
  out->triggered = false;
  FilterRun run;
  run.source = &image;
  run.camera = &camera;
  run.out = out;
  run.work.Reset(image.width, image.height, kSwarmsimColourImage);
  std::memcpy(run.work.pixels.data(), image.rgb.data(),
              std::min(run.work.pixels.size(), image.rgb.size()));
  for (const auto& element : data_->elements) element->Apply(&run);
  ToRgb(run.work, camera, &out->image);
}

FilterChain ParseFilterChain(const ObjectReader& reader, std::string_view key,
                             const ModuleRegistry* registry) {
  const ModuleRegistry& elements = registry != nullptr ? *registry : BuiltinRegistry();
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
