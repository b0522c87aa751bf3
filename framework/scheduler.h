// The task scheduler: a thin wrapper over oneTBB with a serial fallback.
//
// The hot loops are plain parallel-fors over robot ranges with a barrier at
// the end of each call. With one thread everything runs inline on the
// caller, with no TBB involvement. TBB stays out of this header.
#pragma once

#include <cstdint>
#include <memory>

namespace swarmsim {

class TaskScheduler {
 public:
  // threads <= 0: all cores.
  explicit TaskScheduler(int threads);
  ~TaskScheduler();
  TaskScheduler(const TaskScheduler&) = delete;
  TaskScheduler& operator=(const TaskScheduler&) = delete;

  int threads() const { return threads_; }

  // Calls body(begin, end) over disjoint sub-ranges covering [begin, end),
  // each at least `grain` long (except the last), and returns when all are
  // done. Exceptions thrown by the body propagate to the caller.
  template <typename F>
  void ParallelFor(int64_t begin, int64_t end, int64_t grain, F&& body) {
    if (end <= begin) return;
    if (threads_ == 1 || end - begin <= grain) {
      body(begin, end);
      return;
    }
    Run(begin, end, grain, &Trampoline<F>, &body);
  }

  static int HardwareThreads();

 private:
  using RangeFn = void (*)(void* ctx, int64_t begin, int64_t end);
  template <typename F>
  static void Trampoline(void* ctx, int64_t b, int64_t e) {
    (*static_cast<std::remove_reference_t<F>*>(ctx))(b, e);
  }
  void Run(int64_t begin, int64_t end, int64_t grain, RangeFn fn, void* ctx);

  int threads_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmsim
