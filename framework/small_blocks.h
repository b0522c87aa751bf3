// Small blocks without malloc's per-block header, for Lua states (the
// allocator of script_hooks.cc). Lua gives a block's size back when it
// frees or resizes it, so a block needs no header: blocks of up to
// kMaxSmallBlock bytes come in size classes (8-byte steps to 256, then
// 16-byte steps), carved from 64 KiB slabs, and a freed block goes on its
// class's free list. A robot's Lua state is ~400 blocks of ~40 bytes;
// malloc's header and 16-byte rounding cost ~12 bytes each, about 3 KB a
// robot.
//
// Any thread may allocate or free any block (a robot's state runs on
// whichever worker takes it): each thread has its own free lists, and one
// that holds too many blocks of a class passes half to a shared list, from
// which a thread that runs short takes before carving new ones. Slabs are
// never returned to the system: the memory of a finished world's states
// is reused by the next world of the process.
//
// Under AddressSanitizer every block is malloc's own, so that ASan sees
// Lua's heap block by block.
#pragma once

#include <cstddef>

namespace swarmsim::small_blocks {

inline constexpr size_t kMaxSmallBlock = 1024;

// A block of `size` bytes (> 0), aligned to 8 bytes (what Lua needs:
// LUAI_MAXALIGN), or null when out of memory.
void* Allocate(size_t size);
// Gives back a block of Allocate(size) (the same size).
void Free(void* block, size_t size);
// Lua's allocator contract: `old_size` is the block's size (0 for none), a
// new size of 0 frees it. Returns null when out of memory (the block is
// then unchanged), never when shrinking.
void* Resize(void* block, size_t old_size, size_t new_size);

// For tests: bytes of slabs taken from the system so far.
size_t SlabBytes();

}  // namespace swarmsim::small_blocks
