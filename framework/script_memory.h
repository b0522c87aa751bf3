// The memory scripts hold: one account per robot's scripts (one more for
// the scene's scripts and the world's main script) and one for the run.
//
// A robot's account counts its Lua heap (the allocator, script_hooks.cc)
// and every copy of its scripts' data that C++ holds for it: lines printed
// and metrics recorded until the world takes them, messages until the next
// ones are delivered, signals and custom data blocks until overwritten or
// cleared, deferred writes, collections and objects scripts make (for the
// robot's lifetime), strings a sim.* call builds while it runs (CallCharge,
// framework/lua_api.h). Against simulation.script_memory_mb
// the Lua heap may go a little past the limit before the script fails (the
// garbage is collected first); a C++ copy is refused outright.
//
// Threads: a robot's account is touched by one thread at a time (its
// worker during a phase, the world's thread between phases). The run's
// account (simulation.run_script_memory_mb) is shared: a robot takes bytes
// from it in chunks, so most Lua allocations touch only their own account,
// and its atomic only when a chunk runs out or a surplus is given back.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace swarmsim {

// What a robot copied at run time (sim.copyModel) charges its own account,
// taken from the run's whatever its own limit: its scene objects' rows,
// names and poses, about this much an object (a foot-bot's 40 objects,
// 40 KiB). Released when the copy is removed.
constexpr uint64_t kCopyBytesPerObject = 1024;
constexpr uint64_t CopyChargeBytes(size_t objects) { return objects * kCopyBytesPerObject; }

class RunScriptMemory {
 public:
  // 0: no limit.
  void set_limit(uint64_t bytes) { limit_ = bytes; }
  uint64_t limit() const { return limit_; }
  // Bytes the robots' accounts took (a little more than they hold).
  uint64_t taken() const { return taken_.load(std::memory_order_relaxed); }
  // Takes `bytes`; false (nothing taken) if that would pass the limit.
  bool Take(uint64_t bytes) {
    const uint64_t before = taken_.fetch_add(bytes, std::memory_order_relaxed);
    if (limit_ == 0 || before + bytes <= limit_) return true;
    taken_.fetch_sub(bytes, std::memory_order_relaxed);
    return false;
  }
  // Takes `bytes` whatever the limit (what is already held elsewhere).
  void Force(uint64_t bytes) { taken_.fetch_add(bytes, std::memory_order_relaxed); }
  void Give(uint64_t bytes) { taken_.fetch_sub(bytes, std::memory_order_relaxed); }

 private:
  std::atomic<uint64_t> taken_{0};
  uint64_t limit_ = 0;
};

class ScriptMemory {  // 48 bytes
 public:
  enum Result : uint8_t { kOk, kPastLimit, kPastRunLimit };

  // Before anything is counted. `run` null (the default): an account of its
  // own (LimitedLua), no run to answer to.
  void Attach(RunScriptMemory* run, uint64_t limit) {
    run_ = run;
    limit_ = limit;
    reserve_ = run_ != nullptr ? 0 : UINT64_MAX;
    give_back_above_ = run_ != nullptr ? 2 * kMinChunk : UINT64_MAX;
  }
  uint64_t limit() const { return limit_; }  // bytes; 0: no limit
  uint64_t used() const { return used_; }    // Lua heaps + data
  uint64_t data() const { return data_; }    // of which C++ copies of script data
  const RunScriptMemory* run() const { return run_; }
  RunScriptMemory* run() { return run_; }

  // --- The Lua heap (the allocator: hot) -----------------------------------------
  // `bytes` more; false (nothing counted) if the run cannot give them. The
  // robot's own limit is the allocator's to check (it allows some slack).
  bool GrowHeap(uint64_t bytes) {
    if (used_ + bytes > reserve_ && !TakeFromRun(used_ + bytes)) return false;
    used_ += bytes;
    return true;
  }
  void ShrinkHeap(uint64_t bytes) {
    used_ -= bytes;
    if (reserve_ - used_ > give_back_above_) GiveBackToRun();
  }

  // --- Copies of script data -----------------------------------------------------
  // Charges `bytes`: kOk, or (nothing charged) kPastLimit if the robot's
  // scripts would hold more than their limit, kPastRunLimit if the run's.
  Result Charge(uint64_t bytes) {
    if (used_ + bytes < used_ || (limit_ > 0 && used_ + bytes > limit_)) return kPastLimit;
    if (!GrowHeap(bytes)) return kPastRunLimit;
    data_ += bytes;
    return kOk;
  }
  // Charges `bytes` whatever the limits (a copy of blocks already held).
  void Force(uint64_t bytes) {
    if (used_ + bytes > reserve_) {
      const uint64_t more = used_ + bytes - reserve_;
      run_->Force(more);
      reserve_ += more;
    }
    used_ += bytes;
    data_ += bytes;
  }
  void Release(uint64_t bytes) {
    data_ -= bytes;
    ShrinkHeap(bytes);
  }

 private:
  // Smallest chunk taken from the run: ~8 KiB of slack per robot, 80 MiB
  // at 10,000 robots, and an atomic operation every few thousand small
  // allocations at most. A larger holder takes 1/16 of what it holds.
  static constexpr uint64_t kMinChunk = uint64_t{8} << 10;

  // Takes enough from the run for `needed` bytes and one chunk more.
  bool TakeFromRun(uint64_t needed) {
    const uint64_t chunk = std::max(kMinChunk, needed / 16);
    const uint64_t want = needed + chunk;
    if (!run_->Take(want - reserve_)) {
      // Near the run's limit: the bytes themselves, without the chunk.
      if (!run_->Take(needed - reserve_)) return false;
      reserve_ = needed;
      give_back_above_ = 2 * chunk;
      return true;
    }
    reserve_ = want;
    give_back_above_ = 2 * chunk;
    return true;
  }
  // Keeps one chunk of what is left unused.
  void GiveBackToRun() {
    const uint64_t chunk = give_back_above_ / 2;
    run_->Give(reserve_ - used_ - chunk);
    reserve_ = used_ + chunk;
  }

  uint64_t used_ = 0;
  uint64_t data_ = 0;
  uint64_t limit_ = 0;
  uint64_t reserve_ = UINT64_MAX;  // taken from the run (>= used_)
  uint64_t give_back_above_ = UINT64_MAX;
  RunScriptMemory* run_ = nullptr;
};

// What one copy of script data is charged: its bytes and its container's.
inline constexpr uint64_t kHeldEntryBytes = 64;  // a map node or vector slot, a std::string
inline uint64_t CustomDataBytes(size_t tag, size_t data) { return tag + data + kHeldEntryBytes; }
inline uint64_t SignalBytes(size_t name, size_t text) { return name + text + kHeldEntryBytes; }

}  // namespace swarmsim
