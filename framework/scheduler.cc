#include "framework/scheduler.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include <thread>

namespace swarmsim {

struct TaskScheduler::Impl {
  explicit Impl(int threads) : arena(threads) {}
  oneapi::tbb::task_arena arena;
};

int TaskScheduler::HardwareThreads() {
  const int n = oneapi::tbb::info::default_concurrency();
  return n > 0 ? n : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

TaskScheduler::TaskScheduler(int threads)
    : threads_(threads > 0 ? threads : HardwareThreads()) {
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
