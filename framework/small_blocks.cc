// Size-class blocks for Lua states (small_blocks.h).
#include "framework/small_blocks.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "framework/sanitizers.h"

namespace swarmsim::small_blocks {
namespace {

constexpr bool kPooled = !kAddressSanitizer;

// Size classes: 8-byte steps up to 256 bytes (Lua's objects, strings),
// then 16-byte steps up to kMaxSmallBlock (arrays and hash parts of tables,
// prototypes' code): classes 0..31 hold (c + 1) * 8 bytes, 32..79 hold
// 256 + (c - 31) * 16.
constexpr size_t kFine = 256;
constexpr size_t kFineClasses = kFine / 8;
constexpr size_t kClasses = kFineClasses + (kMaxSmallBlock - kFine) / 16;
constexpr size_t kSlabBytes = 64 * 1024;
// A thread holding more free blocks of one class than this passes half of
// them to the shared lists.
constexpr size_t kMaxCached = 4096;

size_t ClassOf(size_t size) {
  return size <= kFine ? (size - 1) / 8 : kFineClasses + (size - kFine - 1) / 16;
}
size_t BytesOf(size_t c) {
  return c < kFineClasses ? (c + 1) * 8 : kFine + (c - kFineClasses + 1) * 16;
}
// The biggest class whose blocks fit in `bytes` (>= 8).
size_t FitClass(size_t bytes) {
  if (bytes <= kFine) return bytes / 8 - 1;
  return std::min(kFineClasses - 1 + (bytes - kFine) / 16, kClasses - 1);
}

struct FreeBlock {
  FreeBlock* next;
};

// A list of free blocks of one class, with its length.
struct FreeList {
  FreeBlock* head = nullptr;
  size_t count = 0;

  void Push(void* block) {
    auto* b = static_cast<FreeBlock*>(block);
    b->next = head;
    head = b;
    ++count;
  }
  void* Pop() {
    FreeBlock* b = head;
    head = b->next;
    --count;
    return b;
  }
  // Moves the first `n` blocks (n <= count) to `to`.
  void MoveTo(FreeList* to, size_t n) {
    for (size_t i = 0; i < n; ++i) to->Push(Pop());
  }
};

// What threads give back and take: one list per class, under one mutex
// (taken once per kMaxCached / 2 frees of a class, and by a thread that
// runs out of a class only when the shared list has some).
struct Shared {
  std::mutex mutex;
  FreeList lists[kClasses];
  // Each list's length, readable without the mutex: a thread whose own list
  // is empty looks here before it locks (most times there is nothing).
  std::atomic<size_t> available[kClasses] = {};

  void Published(size_t c) { available[c].store(lists[c].count, std::memory_order_relaxed); }
};
Shared& SharedLists() {
  static Shared* shared = new Shared;  // never destroyed: threads may outlive statics
  return *shared;
}
std::atomic<size_t> slab_bytes{0};

struct ThreadCache {
  FreeList lists[kClasses];
  char* bump = nullptr;  // the current slab's unused rest
  char* bump_end = nullptr;

  ~ThreadCache();

  void* Carve(size_t c);
};
// Set when the thread's cache is gone (thread exit, or the main thread's
// static destruction): later calls on that thread go to the shared lists.
thread_local bool cache_gone = false;
thread_local ThreadCache cache;

ThreadCache::~ThreadCache() {
  {
    // A finished thread's blocks go to the shared lists (the rest of its
    // slab is lost: at most 64 KiB per thread).
    Shared& shared = SharedLists();
    const std::lock_guard<std::mutex> lock(shared.mutex);
    for (size_t c = 0; c < kClasses; ++c) {
      lists[c].MoveTo(&shared.lists[c], lists[c].count);
      shared.Published(c);
    }
  }
  cache_gone = true;
}

void* ThreadCache::Carve(size_t c) {
  const size_t bytes = BytesOf(c);
  if (static_cast<size_t>(bump_end - bump) < bytes) {
    // The rest of the old slab becomes free blocks of the biggest class
    // that fits, then a new slab.
    while (static_cast<size_t>(bump_end - bump) >= 8) {
      const size_t fit = FitClass(static_cast<size_t>(bump_end - bump));
      lists[fit].Push(bump);
      bump += BytesOf(fit);
    }
    char* slab = static_cast<char*>(std::malloc(kSlabBytes));
    if (slab == nullptr) return nullptr;
    slab_bytes.fetch_add(kSlabBytes, std::memory_order_relaxed);
    bump = slab;
    bump_end = slab + kSlabBytes;
  }
  void* block = bump;
  bump += bytes;
  return block;
}

}  // namespace

void* Allocate(size_t size) {
  // (With the thread's cache gone, malloc's: a block is any memory of its
  // size, and Free then keeps it in the shared lists.)
  if (!kPooled || size > kMaxSmallBlock || cache_gone) return std::malloc(size);
  const size_t c = ClassOf(size);
  FreeList& list = cache.lists[c];
  if (list.count == 0) {
    Shared& shared = SharedLists();
    if (shared.available[c].load(std::memory_order_relaxed) > 0) {
      const std::lock_guard<std::mutex> lock(shared.mutex);
      FreeList& from = shared.lists[c];
      from.MoveTo(&list, std::min(from.count, kMaxCached / 2));
      shared.Published(c);
    }
  }
  if (list.count > 0) return list.Pop();
  return cache.Carve(c);
}

void Free(void* block, size_t size) {
  if (block == nullptr) return;
  if (!kPooled || size > kMaxSmallBlock) {
    std::free(block);
    return;
  }
  if (cache_gone) {
    Shared& shared = SharedLists();
    const std::lock_guard<std::mutex> lock(shared.mutex);
    shared.lists[ClassOf(size)].Push(block);
    shared.Published(ClassOf(size));
    return;
  }
  FreeList& list = cache.lists[ClassOf(size)];
  list.Push(block);
  if (list.count > kMaxCached) {
    Shared& shared = SharedLists();
    const std::lock_guard<std::mutex> lock(shared.mutex);
    list.MoveTo(&shared.lists[ClassOf(size)], kMaxCached / 2);
    shared.Published(ClassOf(size));
  }
}

void* Resize(void* block, size_t old_size, size_t new_size) {
  if (block == nullptr) old_size = 0;
  if (new_size == 0) {
    Free(block, old_size);
    return nullptr;
  }
  if (block == nullptr) return Allocate(new_size);
  const bool old_small = kPooled && old_size <= kMaxSmallBlock;
  const bool new_small = kPooled && new_size <= kMaxSmallBlock;
  if (old_small && new_small && ClassOf(old_size) == ClassOf(new_size)) return block;
  if (!old_small && !new_small) return std::realloc(block, new_size);
  void* moved = Allocate(new_size);
  if (moved == nullptr) {
    // Lua assumes that shrinking never fails: keep the old block, big enough.
    return new_size <= old_size ? block : nullptr;
  }
  std::memcpy(moved, block, std::min(old_size, new_size));
  Free(block, old_size);
  return moved;
}

size_t SlabBytes() { return slab_bytes.load(std::memory_order_relaxed); }

}  // namespace swarmsim::small_blocks
