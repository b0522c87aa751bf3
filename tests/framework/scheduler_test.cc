// The task scheduler (framework/scheduler.cc): a parallel-for that covers a
// range exactly once, whatever the thread count, and brings a worker's
// exception back to the caller (a script error in one robot stops the run
// with that robot's message, not a crash).
#include "framework/scheduler.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

namespace swarmsim {
namespace {

// How often each index of [begin, end) was visited, and the sub-ranges.
struct Coverage {
  explicit Coverage(int64_t begin, int64_t end)
      : begin(begin), visits(static_cast<size_t>(end - begin)) {}
  int64_t begin;
  std::vector<std::atomic<int>> visits;
  std::mutex mutex;
  std::vector<std::pair<int64_t, int64_t>> ranges;
};

void Cover(TaskScheduler* scheduler, Coverage* c, int64_t begin, int64_t end, int64_t grain) {
  scheduler->ParallelFor(begin, end, grain, [c](int64_t b, int64_t e) {
    {
      std::lock_guard<std::mutex> lock(c->mutex);
      c->ranges.emplace_back(b, e);
    }
    for (int64_t i = b; i < e; ++i) c->visits[static_cast<size_t>(i - c->begin)].fetch_add(1);
  });
}

TEST(TaskSchedulerTest, EveryIndexIsVisitedExactlyOnceAtAnyThreadCount) {
  for (int threads : {1, 2, 4}) {
    TaskScheduler scheduler(threads);
    EXPECT_EQ(scheduler.threads(), threads);
    for (int64_t grain : {1, 7, 64, 5000}) {
      for (auto [begin, end] : {std::pair<int64_t, int64_t>{0, 1000}, {-37, 1201}, {5, 6}}) {
        Coverage c(begin, end);
        Cover(&scheduler, &c, begin, end, grain);
        for (size_t i = 0; i < c.visits.size(); ++i)
          ASSERT_EQ(c.visits[i].load(), 1)
              << "index " << begin + static_cast<int64_t>(i) << ", " << threads << " threads";
        for (auto [b, e] : c.ranges) {
          EXPECT_LE(begin, b);
          EXPECT_LT(b, e);
          EXPECT_LE(e, end);
        }
      }
    }
  }
}

TEST(TaskSchedulerTest, AnEmptyOrReversedRangeCallsNothing) {
  for (int threads : {1, 2}) {
    TaskScheduler scheduler(threads);
    int calls = 0;
    scheduler.ParallelFor(5, 5, 1, [&](int64_t, int64_t) { ++calls; });
    scheduler.ParallelFor(9, 3, 1, [&](int64_t, int64_t) { ++calls; });
    EXPECT_EQ(calls, 0);
  }
}

// One thread (or a range no longer than the grain) runs inline, in one call
// on the caller's thread: the serial fallback.
TEST(TaskSchedulerTest, OneThreadRunsTheWholeRangeInlineInOneCall) {
  const std::thread::id caller = std::this_thread::get_id();
  TaskScheduler serial(1);
  std::vector<std::pair<int64_t, int64_t>> calls;
  serial.ParallelFor(0, 100000, 1, [&](int64_t b, int64_t e) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    calls.emplace_back(b, e);
  });
  EXPECT_EQ(calls, (std::vector<std::pair<int64_t, int64_t>>{{0, 100000}}));
  TaskScheduler parallel(2);
  calls.clear();
  parallel.ParallelFor(10, 20, 10, [&](int64_t b, int64_t e) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    calls.emplace_back(b, e);
  });
  EXPECT_EQ(calls, (std::vector<std::pair<int64_t, int64_t>>{{10, 20}}));
}

TEST(TaskSchedulerTest, AnExceptionInTheBodyReachesTheCaller) {
  for (int threads : {1, 2, 4}) {
    TaskScheduler scheduler(threads);
    try {
      scheduler.ParallelFor(0, 1000, 1, [](int64_t b, int64_t e) {
        if (b <= 617 && 617 < e) throw std::runtime_error("robot 617 failed");
      });
      ADD_FAILURE() << threads << " threads: no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "robot 617 failed");
    }
    // The scheduler is still usable afterwards.
    Coverage c(0, 100);
    Cover(&scheduler, &c, 0, 100, 1);
    for (const auto& v : c.visits) EXPECT_EQ(v.load(), 1);
  }
}

TEST(TaskSchedulerTest, ZeroOrNegativeThreadsMeanAllCores) {
  EXPECT_GE(TaskScheduler::HardwareThreads(), 1);
  EXPECT_EQ(TaskScheduler(0).threads(), TaskScheduler::HardwareThreads());
  EXPECT_EQ(TaskScheduler(-3).threads(), TaskScheduler::HardwareThreads());
}

}  // namespace
}  // namespace swarmsim
