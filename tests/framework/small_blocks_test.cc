// Lua's small blocks (framework/small_blocks.h): every size keeps its bytes
// through resizes between classes and to and from malloc's sizes, blocks
// never overlap, freed blocks are reused, and blocks freed on other
// threads than the one that made them come back.
#include "framework/small_blocks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <set>
#include <thread>
#include <vector>

namespace swarmsim::small_blocks {
namespace {

// Fills a block with a pattern of its own; Holds checks it.
void Fill(void* block, size_t size, uint8_t seed) {
  auto* bytes = static_cast<uint8_t*>(block);
  for (size_t i = 0; i < size; ++i) bytes[i] = static_cast<uint8_t>(seed + i * 7);
}
bool Holds(const void* block, size_t size, uint8_t seed) {
  const auto* bytes = static_cast<const uint8_t*>(block);
  for (size_t i = 0; i < size; ++i)
    if (bytes[i] != static_cast<uint8_t>(seed + i * 7)) return false;
  return true;
}

TEST(SmallBlocksTest, EverySizeIsAlignedDistinctAndKeepsItsBytes) {
  struct Block {
    void* at;
    size_t size;
  };
  std::vector<Block> blocks;
  for (size_t size = 1; size <= 2 * kMaxSmallBlock + 8; ++size)
    for (int copy = 0; copy < 3; ++copy) {
      void* at = Allocate(size);
      ASSERT_NE(at, nullptr);
      EXPECT_EQ(reinterpret_cast<uintptr_t>(at) % 8, 0u) << size;
      Fill(at, size, static_cast<uint8_t>(size + copy));
      blocks.push_back({at, size});
    }
  // No two blocks share a byte.
  std::vector<std::pair<uintptr_t, uintptr_t>> spans;
  for (const Block& b : blocks)
    spans.emplace_back(reinterpret_cast<uintptr_t>(b.at),
                       reinterpret_cast<uintptr_t>(b.at) + b.size);
  std::sort(spans.begin(), spans.end());
  for (size_t i = 1; i < spans.size(); ++i) EXPECT_LE(spans[i - 1].second, spans[i].first);
  for (size_t i = 0; i < blocks.size(); ++i)
    EXPECT_TRUE(Holds(blocks[i].at, blocks[i].size, static_cast<uint8_t>(blocks[i].size + i % 3)));
  for (const Block& b : blocks) Free(b.at, b.size);
}

TEST(SmallBlocksTest, ResizeKeepsTheBytesAcrossClassesAndIntoMallocSizes) {
  // Grows a block by steps through every class and past kMaxSmallBlock, then
  // shrinks it back, keeping what fits.
  size_t size = 3;
  void* block = Resize(nullptr, 0, size);
  Fill(block, size, 42);
  for (size_t next : {7u, 8u, 9u, 16u, 17u, 100u, 255u, 256u, 257u, 1000u, 1024u, 1025u, 4000u}) {
    block = Resize(block, size, next);
    ASSERT_NE(block, nullptr);
    EXPECT_TRUE(Holds(block, size, 42)) << size << " -> " << next;
    Fill(block, next, 42);
    size = next;
  }
  for (size_t next : {1100u, 1024u, 300u, 256u, 200u, 24u, 1u}) {
    block = Resize(block, size, next);
    ASSERT_NE(block, nullptr);
    EXPECT_TRUE(Holds(block, next, 42)) << size << " -> " << next;
    size = next;
  }
  EXPECT_EQ(Resize(block, size, 0), nullptr);  // freed
}

TEST(SmallBlocksTest, FreedBlocksAreReusedBeforeNewSlabs) {
  // Warm: a slab with room, then a steady churn of 10,000 blocks of a few
  // sizes takes no new slab after the first round.
  std::vector<void*> blocks(10000);
  for (int round = 0; round < 5; ++round) {
    for (size_t i = 0; i < blocks.size(); ++i) blocks[i] = Allocate(24 + 8 * (i % 4));
    for (size_t i = 0; i < blocks.size(); ++i) Free(blocks[i], 24 + 8 * (i % 4));
  }
  const size_t slabs = SlabBytes();
  for (int round = 0; round < 20; ++round) {
    for (size_t i = 0; i < blocks.size(); ++i) blocks[i] = Allocate(24 + 8 * (i % 4));
    for (size_t i = 0; i < blocks.size(); ++i) Free(blocks[i], 24 + 8 * (i % 4));
  }
  EXPECT_EQ(SlabBytes(), slabs);
}

TEST(SmallBlocksTest, BlocksFreedOnAnotherThreadComeBack) {
  // One thread makes blocks, another frees them, over and over (a robot's
  // state made on the main thread, run and closed on workers): the freed
  // blocks return to the maker through the shared lists instead of piling
  // up, so the slabs stop growing.
  constexpr size_t kBlocks = 20000;
  std::vector<void*> blocks(kBlocks);
  size_t after_warm_up = 0;
  for (int round = 0; round < 30; ++round) {
    for (size_t i = 0; i < kBlocks; ++i) {
      blocks[i] = Allocate(40);
      ASSERT_NE(blocks[i], nullptr);
      Fill(blocks[i], 40, static_cast<uint8_t>(i));
    }
    std::thread freer([&] {
      for (size_t i = 0; i < kBlocks; ++i) {
        EXPECT_TRUE(Holds(blocks[i], 40, static_cast<uint8_t>(i)));
        Free(blocks[i], 40);
      }
    });
    freer.join();
    if (round == 4) after_warm_up = SlabBytes();
  }
  // 20,000 blocks of 40 bytes are 800 KB: 25 rounds more may not add more
  // than the blocks a freer keeps in its own lists when it ends (none).
  EXPECT_LE(SlabBytes(), after_warm_up + 64 * 1024);
}

}  // namespace
}  // namespace swarmsim::small_blocks
