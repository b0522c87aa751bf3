// Where the time of a video goes (modules/rendering/video): the diffusion
// world (worlds/diffusion.yaml) with N robots, seen from above at 640x480.
//
// BM_BuildDrawList/N/segments: the scene's triangles (the simulation's
//   thread, every frame).
// BM_Draw/N: OSMesa drawing them (the recorder's thread).
// BM_Encode: one 640x480 frame of that scene through swscale and x264.
// BM_Png: one 640x480 snapshot through libpng.
// items_per_second counts frames.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <bit>
#include <filesystem>
#include <memory>
#include <string>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/paint/png_io.h"
#include "modules/rendering/geometry.h"
#include "modules/rendering/render.h"
#include "modules/rendering/video/frame_geometry.h"
#include "modules/rendering/video/video_writer.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

struct Diffusion {
  ModuleRegistry registry;
  LoadedWorld loaded;
  rendering::View view;
  explicit Diffusion(int robots) {
    RegisterBuiltinModules(&registry);
    LoadOptions options;
    options.threads = 1;
    options.overrides = {{"robots", std::to_string(robots)}};
    loaded =
        LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml", options, registry);
    loaded.world->set_log_sink([](std::string_view) {});
    loaded.world->Start();
    for (int i = 0; i < 10; ++i) loaded.world->Step();
    view = rendering::ArenaView(*loaded.world, 640, 480);
  }
};

Diffusion& World(int robots) {
  static std::unique_ptr<Diffusion> cached;
  static int cached_robots = -1;
  if (cached_robots != robots) {
    cached.reset();
    cached = std::make_unique<Diffusion>(robots);
    cached_robots = robots;
  }
  return *cached;
}

void BM_BuildDrawList(benchmark::State& state) {
  Diffusion& d = World(static_cast<int>(state.range(0)));
  rendering::DrawList list;
  for (auto _ : state)
    rendering::BuildDrawList(*d.loaded.world, static_cast<int>(state.range(1)), &list);
  state.counters["triangles"] = static_cast<double>(list.xyz.size() / 9);
  uint64_t sum = 0;
  for (float f : list.xyz) sum = sum * 31 + std::bit_cast<uint32_t>(f);
  for (float f : list.normal) sum = sum * 31 + std::bit_cast<uint32_t>(f);
  for (uint8_t c : list.rgb) sum = sum * 31 + c;
  state.SetLabel("checksum " + std::to_string(sum));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BuildDrawList)
    ->Args({1000, 16})
    ->Args({1000, 8})
    ->Args({1000, 6})
    ->Unit(benchmark::kMillisecond);

void BM_Draw(benchmark::State& state) {
  Diffusion& d = World(static_cast<int>(state.range(0)));
  rendering::DrawList list;
  rendering::BuildDrawList(*d.loaded.world, static_cast<int>(state.range(1)), &list);
  Image image;
  for (auto _ : state) rendering::Draw(list, d.view, rendering::DrawOptions{}, &image);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Draw)
    ->Args({10, 8})
    ->Args({1000, 16})
    ->Args({1000, 8})
    ->Args({1000, 6})
    ->Args({1000, 4})
    ->Unit(benchmark::kMillisecond);

// What the recorder does per frame of the arena view: the draw list (the
// simulation's thread), faces turned away dropped, drawing (its own thread).
void BM_Frame(benchmark::State& state) {
  Diffusion& d = World(static_cast<int>(state.range(0)));
  rendering::DrawList list;
  std::vector<uint8_t> closed;
  Image image;
  const int segments = video::SegmentsFor(d.view);
  for (auto _ : state) {
    rendering::BuildDrawList(*d.loaded.world, segments, &list);
    video::MarkClosed(d.loaded.world->scene(), list, &closed);
    video::DropHiddenFaces(d.view, closed, &list);
    rendering::Draw(list, d.view, rendering::DrawOptions{}, &image);
  }
  state.counters["segments"] = segments;
  state.counters["triangles"] = static_cast<double>(list.xyz.size() / 9);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Frame)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

void BM_Encode(benchmark::State& state) {
  Diffusion& d = World(1000);
  Image image;
  rendering::Render(*d.loaded.world, d.view, &image);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("video_bench_" + std::to_string(getpid()) + ".mp4");
  {
    video::VideoSettings settings;
    settings.preset = state.range(0) == 0 ? "ultrafast" : "veryfast";
    video::VideoWriter writer(file, settings);
    for (auto _ : state) writer.Write(image);
    writer.Finish();
  }
  std::filesystem::remove(file);
  state.SetLabel(state.range(0) == 0 ? "ultrafast" : "veryfast");
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Encode)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_Png(benchmark::State& state) {
  Diffusion& d = World(1000);
  Image image;
  rendering::Render(*d.loaded.world, d.view, &image);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("video_bench_" + std::to_string(getpid()) + ".png");
  for (auto _ : state) paint::WritePng(file, image.width, image.height, image.rgb);
  std::filesystem::remove(file);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Png)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
