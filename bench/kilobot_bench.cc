// The Kilobot runtime's share of a step (swarm/kilobot): the native
// controller's step for N robots running worlds/kilobot/gradient.c (built to
// build/plugins/kilobot_gradient.so), called through the plugin ABI with a
// stand-in world API that costs next to nothing, so what is timed is the
// runtime: the copy's lock, swapping the robot's globals in and out, the
// guarded calls, setup/loop, motor and LED bookkeeping. Robots split into
// contiguous ranges over `threads` threads, as the world's workers take them.
//   build/bench/kilobot_bench   (ns per robot-step: "time" / robots)
#include <benchmark/benchmark.h>
#include <dlfcn.h>

#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "framework/plugin_api.h"

namespace {

thread_local double t_time = 0;  // each worker steps its robots on its own clock
constexpr int kStepsPerIteration = 32;

double Time(void*) { return t_time; }
int NumberParameter(void*, int, const char*, double*) { return 0; }
int FindObject(void*, int64_t from, const char* path, int64_t* out) {
  if (std::strcmp(path, "./leftMotor") == 0) return *out = from * 8 + 1, 1;
  if (std::strcmp(path, "./rightMotor") == 0) return *out = from * 8 + 2, 1;
  if (std::strcmp(path, "./led") == 0) return *out = from * 8 + 3, 1;
  return 0;
}
int SetJointTargetVelocity(void*, int, int64_t, double) { return 1; }
double RandomUniform(void*, int robot) { return (robot % 97) / 97.0; }
int SetLed(void*, int, int64_t, double, double, double, int) { return 0; }

struct Controller {
  SwarmsimControllerInit init = nullptr;
  SwarmsimControllerStep step = nullptr;
  SwarmsimControllerCleanup cleanup = nullptr;
  void* user_data = nullptr;
};

int AddController(void* impl, const char*, const char*, SwarmsimControllerInit init,
                  SwarmsimControllerStep step, SwarmsimControllerCleanup cleanup, void* user_data) {
  *static_cast<Controller*>(impl) = {init, step, cleanup, user_data};
  return 0;
}
void SetInfo(void*, const char*, const char*, const char*) {}

const Controller* Load() {
  static Controller controller;
  static bool loaded = false;
  if (!loaded) {
    loaded = true;
    const std::string path = std::string(SWARMSIM_BINARY_DIR) + "/plugins/kilobot_gradient.so";
    void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (library == nullptr) return nullptr;
    auto reg = reinterpret_cast<int (*)(const SwarmsimRegistrar*)>(
        dlsym(library, "swarmsim_plugin_register"));
    SwarmsimRegistrar r{};
    r.impl = &controller;
    r.set_info = SetInfo;
    r.add_controller = AddController;
    if (reg == nullptr || reg(&r) != 0) return nullptr;
  }
  return controller.step != nullptr ? &controller : nullptr;
}

void BM_KilobotStep(benchmark::State& state) {
  const Controller* c = Load();
  if (c == nullptr) {
    state.SkipWithError("build/plugins/kilobot_gradient.so did not load (build it first)");
    return;
  }
  const int robots = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  SwarmsimWorldApi api{};
  api.time = Time;
  api.number_parameter = NumberParameter;
  api.find_object = FindObject;
  api.set_joint_target_velocity = SetJointTargetVelocity;
  api.random_uniform = RandomUniform;
  api.set_led = SetLed;
  std::vector<void*> states(robots);
  char error[1024];
  for (int r = 0; r < robots; ++r) {
    const SwarmsimCallContext context{r, r + 1, nullptr, &api};
    if (c->init(&context, &states[r], error, sizeof error, c->user_data) != 0) {
      state.SkipWithError(error);
      return;
    }
  }
  int64_t step = 0;
  // kStepsPerIteration steps of the robots begin..end-1 (a worker's range).
  const auto run = [&](int begin, int end) {
    char message[1024];
    for (int s = 0; s < kStepsPerIteration; ++s) {
      t_time = static_cast<double>(step + s) / 32;
      for (int r = begin; r < end; ++r) {
        const SwarmsimCallContext context{r, r + 1, nullptr, &api};
        c->step(&context, states[r], message, sizeof message, c->user_data);
      }
    }
  };
  for (auto _ : state) {
    if (threads == 1) {
      run(0, robots);
    } else {
      std::vector<std::thread> workers;
      for (int t = 0; t < threads; ++t)
        workers.emplace_back(run, robots * t / threads, robots * (t + 1) / threads);
      for (std::thread& w : workers) w.join();
    }
    step += kStepsPerIteration;
  }
  state.counters["ns_per_robot_step"] = benchmark::Counter(
      static_cast<double>(robots) * kStepsPerIteration * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert, benchmark::Counter::kIs1000);
  for (int r = 0; r < robots; ++r) {
    const SwarmsimCallContext context{r, r + 1, nullptr, &api};
    c->cleanup(&context, states[r], c->user_data);
  }
}
BENCHMARK(BM_KilobotStep)
    ->Args({1000, 1})
    ->Args({10000, 1})
    ->Args({1000, 2})
    ->Args({10000, 2})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
