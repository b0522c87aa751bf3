// Box2D's timers and allocator, replaced.
//
// These definitions take precedence over libbox2d's: the library calls
// b2Timer and b2Alloc_Default through its PLT, and the dynamic linker binds
// those calls to the executable's definitions (ELF symbol interposition).
// Box2dOverridesAreInPlace() is referenced from plane_world.cc so the
// linker keeps this object.
//
// Timers: Box2D 2.4 times every island solve, broad-phase update and step
// with b2Timer, which calls gettimeofday, only to fill
// b2World::GetProfile() — which swarmsim never reads. With a thousand
// robots, each its own island, that is about 30% of a physics step (perf:
// __vdso_gettimeofday 14% of a whole diffusion run, plus b2Timer itself).
// The box2d-only bench row gets the same timers, so ratios stay fair.
//
// Allocator: Box2D writes through what malloc returned without a look, so
// memory refused (ulimit -v, or a large world on a small machine) was a
// segfault inside the library while a world started. Here a refusal throws
// std::bad_alloc, which unwinds out of the library (C++, built with unwind
// tables) to the world's start or step, which end the run with a message;
// the half-built Box2D world is then only destroyed, never stepped or read
// (framework/world.cc).
#include <box2d/b2_settings.h>
#include <box2d/b2_timer.h>

#include <cstdlib>
#include <new>

b2Timer::b2Timer() : m_start_sec(0), m_start_usec(0) {}
void b2Timer::Reset() {}
float b2Timer::GetMilliseconds() const { return 0.0f; }

void* b2Alloc_Default(int32 size) {
  void* memory = std::malloc(static_cast<size_t>(size > 0 ? size : 1));
  if (memory == nullptr) throw std::bad_alloc();
  return memory;
}
void b2Free_Default(void* memory) { std::free(memory); }

namespace swarmsim::box2d {
bool Box2dOverridesAreInPlace() {
  b2Timer timer;
  void* memory = b2Alloc(1);
  b2Free(memory);
  return timer.GetMilliseconds() == 0.0f && memory != nullptr;
}
}  // namespace swarmsim::box2d
