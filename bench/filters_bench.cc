// Vision-sensor filter chains (modules/rendering/filters) per image, as a
// sensor runs them each time it renders (FilterChain::Run into a reused
// FilterOutput, the sensor's reading). The image: a grey floor with eight
// coloured discs (LEDs of other robots, radius 3 px at 64x48), half of them
// green; RGB only, except for BM_*Depth* (a depth slope from 0.5 m to 4 m).
//
//   BM_Statistics     an empty chain: packet 1 (the 15 statistics) and the image copy
//   BM_StatisticsDepth the same with a depth image
//   BM_HsvBlobs       hsv_threshold (green) + blobs: the target, a few us at 64x48
//   BM_HsvBlobsSensor the same as a vision sensor runs it (packet 1 left to the reader)
//   BM_ColorBlobs     color_threshold + blobs
//   BM_GrayscaleEdges grayscale + edges
//   BM_ResizeHsvBlobs resize to half, hsv_threshold + blobs
//   BM_PointCloudDepth depth + point_cloud (every pixel)
//
// Argument: the image width (height 3/4 of it). 100 robots x 10 Hz with a
// 64x48 sensor is 1,000 images a simulated second: at 5 us an image, 5 ms.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "modules/rendering/filters/filters.h"
#include "tests/modules/rendering/filters/filter_list_reader.h"

namespace swarmsim::filters {
namespace {

using testing::FilterItem;

Image Scene(int width, bool with_depth) {
  const int height = width * 3 / 4;
  Image image;
  image.Resize(width, height);
  if (with_depth) image.depth.resize(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      uint8_t* p = image.Pixel(x, y);
      p[0] = p[1] = p[2] = static_cast<uint8_t>(80 + (x + y) % 16);
      if (with_depth) image.depth[static_cast<size_t>(y) * width + x] = 0.5f + 3.5f * y / height;
    }
  const double radius = 3.0 * width / 64;
  for (int k = 0; k < 8; ++k) {
    const double cx = (k + 0.5) * width / 8, cy = height * (k % 2 ? 0.3 : 0.7);
    const uint8_t green[3] = {30, 220, 60}, red[3] = {230, 40, 30};
    const uint8_t* colour = k % 2 ? green : red;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= radius)
          for (int c = 0; c < 3; ++c) image.Pixel(x, y)[c] = colour[c];
  }
  return image;
}

void RunChain(benchmark::State& state, std::vector<FilterItem> items, bool with_depth = false,
              bool statistics = true) {
  const int width = static_cast<int>(state.range(0));
  const Image image = Scene(width, with_depth);
  const FilterChain chain =
      ParseFilterChain(testing::FilterListReader(std::move(items), nullptr), "filters", nullptr);
  CameraModel camera;
  camera.near = 0.1;
  camera.far = 5;
  FilterOutput out;
  for (auto _ : state) {
    chain.Run(image, camera, &out, statistics);
    benchmark::DoNotOptimize(out.packets.data());
  }
  state.counters["blobs"] = static_cast<double>(out.blobs.size());
}

void BM_Statistics(benchmark::State& state) { RunChain(state, {}); }
void BM_StatisticsDepth(benchmark::State& state) { RunChain(state, {}, true); }
void BM_HsvBlobs(benchmark::State& state) {
  RunChain(state, {{"hsv_threshold", {{"hue", {100, 140}}, {"saturation", {0.5, 1}}}},
                   {"blobs", {{"min_pixels", {4}}}}});
}
void BM_HsvBlobsSensor(benchmark::State& state) {
  RunChain(state,
           {{"hsv_threshold", {{"hue", {100, 140}}, {"saturation", {0.5, 1}}}},
            {"blobs", {{"min_pixels", {4}}}}},
           false, false);
}
void BM_ColorBlobs(benchmark::State& state) {
  RunChain(state, {{"color_threshold", {{"color", {0.12, 0.86, 0.24}}, {"tolerance", {0.1}}}},
                   {"blobs", {}}});
}
void BM_GrayscaleEdges(benchmark::State& state) {
  RunChain(state, {{"grayscale", {}}, {"edges", {{"threshold", {0.3}}}}});
}
void BM_ResizeHsvBlobs(benchmark::State& state) {
  const double w = static_cast<double>(state.range(0));
  RunChain(state, {{"resize", {{"width", {w / 2}}, {"height", {w * 3 / 8}}}},
                   {"hsv_threshold", {{"hue", {100, 140}}, {"saturation", {0.5, 1}}}},
                   {"blobs", {}}});
}
void BM_PointCloudDepth(benchmark::State& state) {
  RunChain(state, {{"depth", {}}, {"point_cloud", {}}}, true);
}

BENCHMARK(BM_Statistics)->Arg(64)->Arg(256);
BENCHMARK(BM_StatisticsDepth)->Arg(64);
BENCHMARK(BM_HsvBlobs)->Arg(64)->Arg(128)->Arg(256);
BENCHMARK(BM_HsvBlobsSensor)->Arg(64);
BENCHMARK(BM_ColorBlobs)->Arg(64)->Arg(256);
BENCHMARK(BM_GrayscaleEdges)->Arg(64)->Arg(256);
BENCHMARK(BM_ResizeHsvBlobs)->Arg(128);
BENCHMARK(BM_PointCloudDepth)->Arg(64);

}  // namespace
}  // namespace swarmsim::filters

BENCHMARK_MAIN();
