// Transparent huge pages for the program's heap. A large world is millions
// of small allocations (objects, rows, Lua states, Box2D bodies); with 4 KiB
// pages the kernel faults each page in on first touch and the TLB misses
// while phases walk them. glibc's malloc asks for transparent huge pages
// when the tunable glibc.malloc.hugetlb=1 is set, which glibc reads only as
// the program starts: so `swarmsim` restarts itself once, first thing in
// main(), with the tunable added to GLIBC_TUNABLES (what a user set there is
// kept). Starting 100,000 Lua robots: 16 s -> 9 s.
#pragma once

#include <cstddef>
#include <string>

namespace swarmsim {

// GLIBC_TUNABLES's value with huge pages asked for: `tunables` (null or
// empty: none) with glibc.malloc.hugetlb=1 added, or "" when it names
// glibc.malloc.hugetlb already (the user's own choice stands).
std::string TunablesWithHugePages(const char* tunables);

// Does SWARMSIM_HUGEPAGES's value (null: unset) turn huge pages off? "0",
// "off", "false" and "no" do (any case).
bool HugePagesTurnedOff(const char* value);
// Is `value` neither off (HugePagesTurnedOff) nor 1, on, true, yes (any
// case) nor empty or unset? RestartWithHugePages warns of it (huge pages
// stay on).
bool HugePagesValueUnclear(const char* value);

// Restarts the program (same executable, same arguments) with
// glibc.malloc.hugetlb=1 in GLIBC_TUNABLES, unless the tunable is set
// already (by a user, or by the restart), SWARMSIM_HUGEPAGES turns it
// off (HugePagesTurnedOff), or the C library is not glibc or malloc is a sanitizer's. Returns
// only when it did not restart (also when the restart failed).
void RestartWithHugePages(char** argv);

// glibc's malloc kept from handing memory back and forth with the kernel
// while a large world is built: blocks under 32 MiB come from the heap (not
// a mapping of their own, faulted in anew each time a vector grows), 64 MiB
// of padding each time the heap grows, and up to 512 MiB free at its top
// kept rather than trimmed. Starting 100,000 Lua robots: 164,000 page
// faults -> 4,000. No-op outside glibc.
void TuneMalloc();

// Whether this process's malloc was asked for huge pages (summary.json's
// `huge_pages`). Whether the kernel gives them is its own setting
// (/sys/kernel/mm/transparent_hugepage/enabled: `always` or `madvise`).
bool HugePagesRequested();

// The main thread's stack may grow to 8 MiB (the usual default) when a
// lower `ulimit -s` allows it (its hard limit): Lua stops a script's deep
// recursion through C calls (string.gsub calling a Lua function that calls
// it again) after 200 levels, which took more than 256-400 KiB, and the
// program died of a segfault instead of the script's "C stack overflow".
// A limit of 8 MiB or more is kept. Whether the thread has that room now
// (false: the hard limit is lower; run the program on a thread with a
// stack of kStackForDeepCalls).
inline constexpr size_t kStackForDeepCalls = size_t{8} << 20;
bool RoomForDeepCalls();

}  // namespace swarmsim
