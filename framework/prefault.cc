#include "framework/prefault.h"

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include <algorithm>
#include <atomic>

#include "framework/scheduler.h"

#if defined(__linux__) && !defined(MADV_POPULATE_WRITE)
#define MADV_POPULATE_WRITE 23  // Linux 5.14 (uapi asm-generic/mman-common.h)
#endif

namespace swarmsim {

namespace {

size_t PageSize() {
#if defined(__linux__)
  static const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  return page;
#else
  return 4096;
#endif
}

// A chunk is a few huge pages: large enough that the calls cost nothing
// against the zeroing, small enough to spread a few hundred MiB evenly.
constexpr uintptr_t kChunk = uintptr_t{8} << 20;

}  // namespace

void Prefault::Add(const void* begin, size_t bytes) {
  const uintptr_t page = PageSize();
  const uintptr_t b = (reinterpret_cast<uintptr_t>(begin) + page - 1) / page * page;
  const uintptr_t e = (reinterpret_cast<uintptr_t>(begin) + bytes) / page * page;
  if (bytes == 0 || e <= b) return;
  ranges_.emplace_back(b, e);
}

size_t Prefault::bytes() const {
  size_t n = 0;
  for (const auto& [b, e] : ranges_) n += e - b;
  return n;
}

size_t Prefault::Run(TaskScheduler& scheduler, const std::function<bool()>& stopped) {
  std::vector<std::pair<uintptr_t, uintptr_t>> chunks;
  for (const auto& [b, e] : ranges_)
    for (uintptr_t at = b; at < e; at += kChunk) chunks.emplace_back(at, std::min(e, at + kChunk));
  ranges_.clear();
  std::atomic<size_t> populated{0};
  std::atomic<bool> stop{false};
#if defined(__linux__)
  scheduler.ParallelFor(0, static_cast<int64_t>(chunks.size()), 1, [&](int64_t lo, int64_t hi) {
    size_t done = 0;
    for (int64_t i = lo; i < hi; ++i) {
      if (stop.load(std::memory_order_relaxed)) break;
      if (stopped && stopped()) {
        stop.store(true);
        break;
      }
      const auto [b, e] = chunks[static_cast<size_t>(i)];
      // A failure (EINVAL before Linux 5.14) only means the pages are
      // touched later, when written.
      if (madvise(reinterpret_cast<void*>(b), e - b, MADV_POPULATE_WRITE) == 0) done += e - b;
    }
    populated += done;
  });
#else
  (void)scheduler;
  (void)stopped;
#endif
  return populated.load();
}

}  // namespace swarmsim
