#include "swarm/run/huge_pages.h"

#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "framework/memory_forecast.h"
#include "framework/sanitizers.h"

namespace swarmsim {

namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";

}  // namespace

std::string TunablesWithHugePages(const char* tunables) {
  const std::string given = tunables != nullptr ? tunables : "";
  if (given.find(kTunable) != std::string::npos) return "";
  const std::string ours = std::string(kTunable) + "=1";
  return given.empty() ? ours : given + ":" + ours;
}

bool HugePagesTurnedOff(const char* value) { return IsOffValue(value); }

bool HugePagesValueUnclear(const char* value) {
  return value != nullptr && value[0] != '\0' && !IsOffValue(value) && !IsOnValue(value);
}

void RestartWithHugePages(char** argv) {
#if defined(__GLIBC__) && !defined(__SANITIZE_THREAD__)
  if (kAddressSanitizer) return;  // malloc is ASan's: the tunable does not apply
  if (HugePagesTurnedOff(std::getenv("SWARMSIM_HUGEPAGES"))) return;
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const std::string value = TunablesWithHugePages(tunables);
  if (value.empty()) return;
  // Said by the process that restarts (once): a value meant to turn them off.
  if (const char* asked = std::getenv("SWARMSIM_HUGEPAGES"); HugePagesValueUnclear(asked))
    std::fprintf(stderr,
                 "warning: SWARMSIM_HUGEPAGES='%s' is neither 0, off, false, no nor 1, on, true, "
                 "yes: huge pages stay on\n",
                 asked);
  const std::string kept = tunables != nullptr ? tunables : "";
  const bool had = tunables != nullptr;
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Not restarted (no /proc, say): go on as we are, and say so truthfully.
  if (had)
    setenv("GLIBC_TUNABLES", kept.c_str(), 1);
  else
    unsetenv("GLIBC_TUNABLES");
#else
  (void)argv;
#endif
}

void TuneMalloc() {
#if defined(__GLIBC__) && !defined(__SANITIZE_THREAD__)
  if (kAddressSanitizer) return;
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TOP_PAD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
}

bool HugePagesRequested() {
#if defined(__GLIBC__) && !defined(__SANITIZE_THREAD__)
  // hugetlb=1 (madvise, ours) or 2 (a user's preallocated huge pages).
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (kAddressSanitizer || tunables == nullptr) return false;
  const std::string value(tunables);
  return value.find(std::string(kTunable) + "=1") != std::string::npos ||
         value.find(std::string(kTunable) + "=2") != std::string::npos;
#else
  return false;
#endif
}

bool RoomForDeepCalls() {
  constexpr rlim_t kWanted = kStackForDeepCalls;
  rlimit stack{};
  if (getrlimit(RLIMIT_STACK, &stack) != 0) return true;  // (nothing known: as it is)
  if (stack.rlim_cur == RLIM_INFINITY || stack.rlim_cur >= kWanted) return true;
  if (stack.rlim_max != RLIM_INFINITY && stack.rlim_max < kWanted) return false;
  stack.rlim_cur = kWanted;
  return setrlimit(RLIMIT_STACK, &stack) == 0;
}

}  // namespace swarmsim
