// What `physics: planar` trades against `physics: box2d` on diffusion
// (worlds/diffusion.yaml and worlds/diffusion_planar.yaml: the same robots,
// controller and seed). One run of STEPS steps per backend; counters:
//   free_path_m      mean distance driven between collisions (a collision: a
//                    robot starts touching another robot or a wall, within
//                    1 mm)
//   collisions       collision events per robot per 100 s
//   wall_pen_max_mm  deepest a robot went into a wall, over the run
//   robot_pen_max_mm deepest two robots overlapped, over the run
//   physics_us       physics phase, us per robot-tick
//   ticks_per_s      whole step, robot-ticks per second
//   build/bench/planar_contact_bench [--benchmark_filter=...]
// Args: robots, threads. SWARMSIM_STEPS (default 600) sets the run length.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

constexpr double kRadius = 0.085;  // m, the foot-bot's body (worlds/models/footbot.yaml)
constexpr double kTouch = 1e-3;    // m, gap that still counts as touching
constexpr double kDensity = 1.0;   // robots per m^2 (diffusion.yaml)

void RunDiffusion(benchmark::State& state, const char* world_file) {
  const int robots = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const char* steps_env = std::getenv("SWARMSIM_STEPS");
  const int steps = steps_env ? std::atoi(steps_env) : 600;
  for (auto _ : state) {
    ModuleRegistry registry;
    RegisterBuiltinModules(&registry);
    LoadOptions options;
    options.threads = threads;
    options.seed = 1;
    options.overrides = {{"robots", std::to_string(robots)}};
    LoadedWorld loaded =
        LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/" + world_file, options, registry);
    World& world = *loaded.world;
    world.set_log_sink([](std::string_view) {});
    world.Start();
    const Scene& scene = world.scene();
    std::vector<uint32_t> bodies;  // slots of the robots' bodies
    for (uint32_t row = 0; row < scene.shapes().size(); ++row)
      if (scene.shapes()[row].dynamic) bodies.push_back(scene.shape_owners()[row]);
    const size_t n = bodies.size();
    const double half = 0.5 * std::sqrt(robots / kDensity);  // inner half side of the arena
    std::vector<double> x(n), y(n);
    std::vector<char> touching(n, 0);
    const auto read = [&] {
      for (size_t i = 0; i < n; ++i) {
        x[i] = scene.world_pose_at(bodies[i]).p.x;
        y[i] = scene.world_pose_at(bodies[i]).p.y;
      }
    };
    read();
    std::vector<double> last_x = x, last_y = y;
    double path = 0, wall_pen = 0, robot_pen = 0;
    long collisions = 0;
    const PhaseTimes before = world.phase_times();
    double stepping = 0;
    // Cell lists for the pairs (2r + touch cells).
    const double cell = 2 * kRadius + kTouch;
    const int cells = static_cast<int>(std::ceil(2 * half / cell)) + 2;
    std::vector<std::vector<uint32_t>> grid(static_cast<size_t>(cells) * cells);
    const auto cell_of = [&](double v) {
      return std::clamp(static_cast<int>((v + half) / cell) + 1, 0, cells - 1);
    };
    for (int s = 0; s < steps; ++s) {
      const auto t0 = std::chrono::steady_clock::now();
      world.Step();
      stepping += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      read();
      for (auto& g : grid) g.clear();
      for (size_t i = 0; i < n; ++i) {
        path += std::hypot(x[i] - last_x[i], y[i] - last_y[i]);
        grid[static_cast<size_t>(cell_of(x[i])) * cells + cell_of(y[i])].push_back(
            static_cast<uint32_t>(i));
      }
      last_x = x;
      last_y = y;
      for (size_t i = 0; i < n; ++i) {
        // Walls: the inner faces at +-half.
        const double out = std::max(std::abs(x[i]), std::abs(y[i])) + kRadius - half;
        bool touch = out >= -kTouch;
        wall_pen = std::max(wall_pen, out);
        const int cx = cell_of(x[i]), cy = cell_of(y[i]);
        for (int gx = std::max(cx - 1, 0); gx <= std::min(cx + 1, cells - 1); ++gx)
          for (int gy = std::max(cy - 1, 0); gy <= std::min(cy + 1, cells - 1); ++gy)
            for (uint32_t j : grid[static_cast<size_t>(gx) * cells + gy]) {
              if (j == i) continue;
              const double gap = std::hypot(x[i] - x[j], y[i] - y[j]) - 2 * kRadius;
              if (gap < kTouch) touch = true;
              robot_pen = std::max(robot_pen, -gap);
            }
        if (touch && !touching[i]) ++collisions;
        touching[i] = touch;
      }
    }
    const double ticks = static_cast<double>(n) * steps;
    const double seconds = steps * world.settings().time_step;
    state.counters["free_path_m"] = collisions > 0 ? path / collisions : path;
    state.counters["collisions"] = collisions * 100.0 / seconds / static_cast<double>(n);
    state.counters["wall_pen_max_mm"] = 1e3 * wall_pen;
    state.counters["robot_pen_max_mm"] = 1e3 * robot_pen;
    state.counters["physics_us"] = 1e6 *
                                   (world.phase_times()[static_cast<int>(Phase::kPhysics)] -
                                    before[static_cast<int>(Phase::kPhysics)]) /
                                   ticks;
    state.counters["ticks_per_s"] = ticks / stepping;
  }
}

void BM_Box2d(benchmark::State& state) { RunDiffusion(state, "diffusion.yaml"); }
void BM_Planar(benchmark::State& state) { RunDiffusion(state, "diffusion_planar.yaml"); }

BENCHMARK(BM_Box2d)->Args({1000, 2})->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_Planar)->Args({1000, 2})->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
