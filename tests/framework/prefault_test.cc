// Prefault (framework/prefault.h): the reserved room of arrays about to be
// filled is populated on the scheduler's threads, values untouched; and the
// scene's ReserveForCopies names the copies' room.
#include "framework/prefault.h"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <vector>

#include "framework/scene.h"
#include "framework/scheduler.h"

namespace swarmsim {
namespace {

// How many of the whole pages in [begin, begin + bytes) are resident.
size_t ResidentPages(const void* begin, size_t bytes) {
  const uintptr_t page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
  const uintptr_t b = (reinterpret_cast<uintptr_t>(begin) + page - 1) / page * page;
  const uintptr_t e = (reinterpret_cast<uintptr_t>(begin) + bytes) / page * page;
  if (e <= b) return 0;
  std::vector<unsigned char> in((e - b) / page);
  if (mincore(reinterpret_cast<void*>(b), e - b, in.data()) != 0) return SIZE_MAX;
  size_t n = 0;
  for (unsigned char c : in) n += c & 1;
  return n;
}

// Does this kernel populate on request (MADV_POPULATE_WRITE, Linux 5.14)?
bool KernelPopulates() {
  const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  void* p = mmap(nullptr, page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) return false;
  const bool ok = madvise(p, page, 23 /* MADV_POPULATE_WRITE */) == 0;
  munmap(p, page);
  return ok;
}

TEST(PrefaultTest, ReservedRoomIsPopulatedOnEveryThreadAndValuesKept) {
  if (!KernelPopulates()) GTEST_SKIP() << "this kernel has no MADV_POPULATE_WRITE (Linux < 5.14)";
  // 64 MiB: a fresh mapping of its own, nothing touched past the first rows.
  std::vector<uint64_t> v;
  v.reserve(size_t{8} << 20);
  for (uint64_t i = 0; i < 1000; ++i) v.push_back(i * i);
  const uint64_t* spare = v.data() + v.size();
  const size_t spare_bytes = (v.capacity() - v.size()) * sizeof(uint64_t);
  const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  ASSERT_LT(ResidentPages(spare, spare_bytes), spare_bytes / page / 2)
      << "a fresh reservation should not be resident yet";

  Prefault prefault;
  prefault.AddSpare(v);
  EXPECT_GE(prefault.bytes(), spare_bytes - 2 * page);
  EXPECT_LE(prefault.bytes(), spare_bytes);
  const size_t expected = prefault.bytes();
  TaskScheduler scheduler(2);
  const size_t populated = prefault.Run(scheduler);
  EXPECT_EQ(populated, expected) << "every whole page";
  const size_t whole = ResidentPages(spare, spare_bytes);
  EXPECT_EQ(whole * page, populated) << "every whole page of the room is there";
  EXPECT_EQ(prefault.bytes(), 0u) << "Run forgets the ranges";
  for (uint64_t i = 0; i < 1000; ++i) ASSERT_EQ(v[i], i * i);
  // The room is usable as before.
  v.resize(v.capacity());
  EXPECT_EQ(v[1000], 0u);
}

TEST(PrefaultTest, RangesUnderAPageAddNothing) {
  std::vector<char> small(100);
  Prefault prefault;
  prefault.Add(small.data(), small.size());
  prefault.Add(small.data(), 0);
  EXPECT_EQ(prefault.bytes(), 0u);
  TaskScheduler scheduler(1);
  EXPECT_EQ(prefault.Run(scheduler), 0u);
}

TEST(PrefaultTest, ReserveGrowsKeepingTheContentsAndNamesOnlyTheNewRoom) {
  const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  std::vector<uint32_t> v = {7, 8, 9};
  Prefault prefault;
  prefault.Reserve(v, 3 * page);  // room for 12 pages of uint32_t
  ASSERT_GE(v.capacity(), 3 * page);
  EXPECT_EQ(v, (std::vector<uint32_t>{7, 8, 9})) << "the contents are kept";
  const size_t spare = (v.capacity() - v.size()) * sizeof(uint32_t);
  EXPECT_GE(prefault.bytes(), spare - 2 * page);
  EXPECT_LE(prefault.bytes(), spare);
  // Room enough already: nothing more to populate, the vector untouched.
  const size_t before = prefault.bytes();
  const uint32_t* data = v.data();
  prefault.Reserve(v, 2 * page);
  prefault.Reserve(v, v.capacity());
  EXPECT_EQ(prefault.bytes(), before);
  EXPECT_EQ(v.data(), data);
  TaskScheduler scheduler(2);
  prefault.Run(scheduler);
  v.resize(3 * page);
  EXPECT_EQ(v[2], 9u);
  EXPECT_EQ(v[3], 0u);
}

TEST(PrefaultTest, ReservingForCopiesNamesEveryArrayTheCopiesFill) {
  Scene scene;
  ShapeData body;
  body.kind = ShapeKind::kCylinder;
  body.dynamic = true;
  const ObjectId root = scene.AddShape("body", {}, {}, body);
  for (const char* name : {"d0", "d1", "d2", "d3", "d4", "d5"}) scene.AddDummy(name, root, {});
  scene.MakeModelInstance(root, "bot", "bot#0");
  constexpr size_t kCopies = 20000;
  Prefault prefault;
  scene.ReserveForCopies(root, kCopies, &prefault);
  // At least both poses of every copied object (7 per copy).
  EXPECT_GE(prefault.bytes(), kCopies * 7 * 2 * sizeof(Pose));
  TaskScheduler scheduler(2);
  prefault.Run(scheduler);
  // The copies are made as without it.
  for (size_t k = 0; k < 3; ++k) {
    const Pose X_WR{{double(k), 0, 0}, {}};
    const ObjectId copy = scene.DuplicateSubtree(root, {}, &X_WR);
    EXPECT_EQ(scene.world_pose(copy).p.x, double(k));
    EXPECT_FALSE(scene.FindObject("./d5", copy).IsNull());
  }
}

}  // namespace
}  // namespace swarmsim
