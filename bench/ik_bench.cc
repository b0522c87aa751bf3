// 6-DoF position + orientation IK (UR5, damped least squares) from a nearby
// start: the target is a median of at most 20 us per solve.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "modules/kinematics/chain.h"
#include "modules/kinematics/ik_solver.h"
#include "tests/modules/kinematics/kinematics_test.h"

namespace swarmsim::kinematics {
namespace {

void BM_Ur5PoseIkFromNearbyStart(benchmark::State& state) {
  Scene scene;
  const auto arm = testing::AddUr5(&scene);
  IkProblem ik;
  ik.AddElement(Chain::FromScene(scene, arm.base, arm.tip), {});
  const double nudge_rad = static_cast<double>(state.range(0)) / 1000;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), nudge(-nudge_rad, nudge_rad);
  // 256 problems, cycled.
  std::vector<std::vector<double>> starts;
  std::vector<Pose> targets;
  for (int k = 0; k < 256; ++k) {
    std::vector<double> goal(6), q(6);
    for (int i = 0; i < 6; ++i) {
      goal[i] = angle(rng);
      q[i] = goal[i] + nudge(rng);
    }
    starts.push_back(q);
    targets.push_back(ik.chain(0).CalcTipPose(goal));
  }
  int64_t k = 0, solved = 0, iterations = 0;
  for (auto _ : state) {
    std::vector<double> q = starts[k & 255];
    ik.set_target(0, targets[k & 255]);
    const IkResult r = ik.Solve({}, &q);
    solved += r.solved;
    iterations += r.iterations;
    benchmark::DoNotOptimize(q.data());
    ++k;
  }
  state.counters["solved_%"] = 100.0 * static_cast<double>(solved) / static_cast<double>(k);
  state.counters["iterations"] = static_cast<double>(iterations) / static_cast<double>(k);
}
// Start within +-50 mrad and +-200 mrad of the goal, per joint.
BENCHMARK(BM_Ur5PoseIkFromNearbyStart)->Arg(50)->Arg(200)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace swarmsim::kinematics

BENCHMARK_MAIN();
