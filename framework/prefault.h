// Touching reserved memory on every thread before it is written.
//
// The kernel zeroes a fresh page the first time it is touched, on the thread
// that touches it. A large world's copies write a few GiB of reserved rows
// one robot after another, so most of their time was that zeroing, on one
// thread. Prefault collects the reserved (not yet used) part of the arrays
// about to be filled and asks the kernel to populate it in chunks spread over
// the scheduler's threads (madvise MADV_POPULATE_WRITE, Linux 5.14+); the
// copies then write to pages already there. It changes no value: where the
// kernel cannot populate (an older kernel, not Linux), the pages are touched
// when written, as before.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

namespace swarmsim {

class TaskScheduler;

class Prefault {
 public:
  // The spare capacity of `v`: from its end to its capacity.
  template <typename T>
  void AddSpare(const std::vector<T>& v) {
    Add(v.data() + v.size(), (v.capacity() - v.size()) * sizeof(T));
  }
  // Room for `n` elements in `v` (its contents kept): when it must grow,
  // the room it grew to is added, for Run to populate before `v` is filled
  // to `n`. Clear `v` first when its contents are not needed (growing does
  // not copy them then).
  template <typename T>
  void Reserve(std::vector<T>& v, size_t n) {
    if (v.capacity() >= n) return;
    v.reserve(n);
    AddSpare(v);
  }
  // [begin, begin + bytes): memory the caller owns. The whole pages inside it
  // are populated; ranges under a page add nothing.
  void Add(const void* begin, size_t bytes);
  // The bytes of the whole pages added so far.
  size_t bytes() const;
  // Populates everything added, in chunks over the scheduler's threads (on
  // the caller alone with one thread), and forgets the ranges. Returns the
  // bytes the kernel populated (0 where it cannot). `stopped` (if given) is
  // asked before each chunk (8 MiB): once it says true the rest are left
  // (a stop signal while a million robots' arrays, ~10 GiB, are populated).
  size_t Run(TaskScheduler& scheduler, const std::function<bool()>& stopped = {});

 private:
  std::vector<std::pair<uintptr_t, uintptr_t>> ranges_;  // [begin, end), page-aligned
};

}  // namespace swarmsim
