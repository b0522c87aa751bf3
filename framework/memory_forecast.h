// Refuses, with a message, a world that will not fit in memory, before the
// kernel's out-of-memory killer ends the run without one.
//
// While many like items are built (a large world's robot copies, their Lua
// states), a MemoryForecast measures how much the process's resident size
// grows per item (from the first checkpoint, at 1,000 items or 1/64 of the
// way, on), and, once an eighth of the items are built, at every further
// checkpoint compares what the rest would need with the room left: the
// machine's available memory (MemAvailable + SwapFree), its cgroup's (a
// container's or a cluster job's limit less what the group holds, its page
// cache not counted; cgroup v2 and v1), the process's own limits (ulimit -v
// less its virtual size, ulimit -d less its data size), and a cap the user
// set (`swarmsim run --max-memory`), whichever is smallest. Past it the check returns an
// error naming how many items fit. It never refuses a world of fewer than
// 2,000 items, nor anything when SWARMSIM_MEMORY_CHECK is 0, off, false or
// no.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

namespace swarmsim {

// What the process holds and may still take, in bytes.
struct MemoryRoom {
  uint64_t resident = 0;            // resident size now (/proc/self/statm)
  uint64_t available = UINT64_MAX;  // more it may take; UINT64_MAX: unknown
  std::string bound;                // what `available` is ("--max-memory 2 GiB", ...)
};

// Worlds of fewer robots are not forecast or checked (nor held to a cap).
inline constexpr int64_t kForecastMinRobots = 2000;

// Reads the room left; `cap`: bytes the whole process may hold (0: none).
MemoryRoom ReadMemoryRoom(uint64_t cap);

// "1.5 GiB", "300 MiB", "16.9 KiB": a decimal below 100 of a unit (a
// robot's share; script_state.h's FormatBytes gives whole MiB and KiB).
std::string FormatSize(double bytes);

// 1234567 -> "1,234,567" (negative: "0"), as the progress lines print counts.
std::string GroupThousands(int64_t n);

// Parses a size: "500M", "2G", "2GiB", "1.5g", "4096" (bytes); K/M/G/T are
// powers of 1024. False on anything else (or zero).
bool ParseMemorySize(const std::string& text, uint64_t* bytes);

// Whether an environment variable's value turns a feature off: 0, off,
// false or no, any case (SWARMSIM_MEMORY_CHECK, SWARMSIM_HUGEPAGES).
bool IsOffValue(const char* value);
// Whether it turns a feature on: 1, on, true or yes, any case.
bool IsOnValue(const char* value);

// After a stage that takes memory in proportion to a world's robots (its
// start: physics, each module, ...): the error text when the process has no
// room left (it holds its cap or its cgroup's limit already), naming the
// stage (`after`: "starting module proximity"), else "". Nothing for fewer
// than 2,000 robots or with the check off, as MemoryForecast.
std::string NoRoomLeft(int64_t robots, const std::string& after, uint64_t cap);

class MemoryForecast {
 public:
  // `items`: what is built, plural ("robot copies", "robots' Lua states");
  // `total`: how many; `cap`: as ReadMemoryRoom's.
  MemoryForecast(std::string items, int64_t total, uint64_t cap);

  // Notes that `built` items of `total` are built (any thread; each count
  // once). At a checkpoint, reads the memory and returns the error text
  // when the rest will not fit; "" otherwise.
  std::string Built(int64_t built);
  // Built measures only when `built` is a multiple of this (0: never): a
  // caller building items in batches ends a batch there.
  int64_t stride() const { return stride_; }

  // Before the items are built: `bytes` of memory reserved for all of them
  // that building them will touch (a loader's arrays for every copy, about
  // to be populated at once: framework/prefault.h). The error text when
  // those bytes alone exceed the room left; "" otherwise, and under the
  // same rules as Built (nothing for fewer than 2,000 items or with the
  // check off). Without it, populating them could end the process through
  // the kernel's out-of-memory killer before any checkpoint.
  std::string Reserved(uint64_t bytes) const;
  // The error text when reserving those arrays failed (std::bad_alloc:
  // ulimit -v, or an overcommit the kernel refused) after `bytes` of them.
  std::string ReserveFailed(uint64_t bytes) const;

  // The check, for a given reading (tests): `built` of `total` items are
  // built, the last `measured` of them grew the process by `grown` bytes.
  // "" when the rest fits.
  static std::string Verdict(const std::string& items, int64_t total, int64_t built,
                             int64_t measured, uint64_t grown, const MemoryRoom& room);

 private:
  std::string items_;
  int64_t total_;
  uint64_t cap_;
  int64_t stride_ = 0;                      // items between checkpoints; 0: no checks
  std::atomic<uint64_t> base_resident_{0};  // at the first checkpoint
  std::atomic<bool> refused_{false};
};

}  // namespace swarmsim
