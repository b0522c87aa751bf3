// Free profiling timers for Box2D.
//
// Box2D 2.4 times every island solve, broad-phase update and step with
// b2Timer, which calls gettimeofday, only to fill b2World::GetProfile() —
// which swarmsim never reads. With a thousand robots, each its own island,
// that is about 30% of a physics step (perf: __vdso_gettimeofday 14% of a
// whole diffusion run, plus b2Timer itself).
//
// These definitions take precedence over libbox2d's: the library calls
// b2Timer through its PLT, and the dynamic linker binds those calls to the
// executable's definitions (ELF symbol interposition). The box2d-only bench
// row gets the same timers, so ratios stay fair. Box2dTimerIsOverridden()
// is referenced from plane_world.cc so the linker keeps this object.
#include <box2d/b2_timer.h>

b2Timer::b2Timer() : m_start_sec(0), m_start_usec(0) {}
void b2Timer::Reset() {}
float b2Timer::GetMilliseconds() const { return 0.0f; }

namespace swarmsim::box2d {
bool Box2dTimerIsOverridden() {
  b2Timer timer;
  return timer.GetMilliseconds() == 0.0f;
}
}  // namespace swarmsim::box2d
