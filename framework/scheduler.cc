#include "framework/scheduler.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <thread>

namespace swarmsim {

struct TaskScheduler::Impl {
  // TBB caps its worker pool at the core count; asking for more threads than
  // cores (to test determinism at 4 threads on 2 cores, say) raises the cap
  // for as long as this scheduler lives.
  explicit Impl(int threads)
      : allow(oneapi::tbb::global_control::max_allowed_parallelism,
              static_cast<size_t>(std::max(threads, HardwareThreads()))),
        arena(threads) {}
  oneapi::tbb::global_control allow;
  oneapi::tbb::task_arena arena;
};

int TaskScheduler::HardwareThreads() {
  const int n = oneapi::tbb::info::default_concurrency();
  return n > 0 ? n : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

TaskScheduler::TaskScheduler(int threads) : threads_(threads > 0 ? threads : HardwareThreads()) {
  if (threads_ > 1) impl_ = std::make_unique<Impl>(threads_);
}

TaskScheduler::~TaskScheduler() = default;

void TaskScheduler::Run(int64_t begin, int64_t end, int64_t grain, RangeFn fn, void* ctx) {
  impl_->arena.execute([&] {
    oneapi::tbb::parallel_for(
        oneapi::tbb::blocked_range<int64_t>(begin, end, grain > 0 ? grain : 1),
        [&](const oneapi::tbb::blocked_range<int64_t>& r) { fn(ctx, r.begin(), r.end()); },
        oneapi::tbb::auto_partitioner());
  });
}

}  // namespace swarmsim
