// ODE for the whole process: initialisation, the error handlers, and the
// program's own dRandInt with the probes that check how ODE's solver can use
// threads (ode_threading.h). Internal to the ODE module.
#include <ode/ode.h>

#include <atomic>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <new>
#include <string>

#include "framework/error.h"
#include "modules/dynamics/ode/ode_internal.h"
#include "modules/dynamics/ode/ode_threading.h"
#include "modules/dynamics/ode/ode_world.h"

namespace swarmsim::ode {
namespace {
// Set when ODE calls the dRandInt below (ProbeSolverShuffle).
std::atomic<bool> g_shuffle_called{false};
}  // namespace
}  // namespace swarmsim::ode

// ODE's quickstep shuffles its constraint rows (every 8th iteration, per
// island) with `swap(order[i], order[dRandInt(i + 1)])`, and dRandInt is
// ODE's only use of its random generator: one process-global seed. Stepped
// islands on several threads, the draws interleave in whatever order the
// threads run, so the state would depend on the thread count and timing.
// This definition takes the place of ODE's (the program's own definition of
// an exported function comes first when libode's call is bound, the usual
// ELF rule). While an island is solved, the draws come from that island's
// stream (SolverThreads::DrawShuffle: seeded by the step, the same whichever
// thread solves the island); elsewhere (ODE's multi-threaded path, where an
// island's solve is split into calls) the draw is a fixed function of n.
// InitOdeOnce checks that ODE calls this one (ProbeSolverShuffle); if not,
// the solver stays on one thread.
extern "C" __attribute__((visibility("default"))) int dRandInt(int n) {
  std::atomic<bool>& called = swarmsim::ode::g_shuffle_called;
  if (!called.load(std::memory_order_relaxed)) called.store(true, std::memory_order_relaxed);
  int draw;
  if (swarmsim::ode::SolverThreads::DrawShuffle(n, &draw)) return draw;
  return swarmsim::ode::Below(
      swarmsim::ode::Mix64(static_cast<uint64_t>(n) * 0x9e3779b97f4a7c15ULL), n);
}

namespace swarmsim::ode {

namespace {

// ODE's error and debug handlers: ODE calls them on an internal assertion
// (huge or degenerate geometry) and aborts the process if they return. Ours
// throws instead, so the run ends with an error and its outputs written;
// the unwinding leaves that ODE world unusable, and the World stops after
// any physics error anyway.
[[noreturn]] void ThrowOdeError(int number, const char* message, va_list arguments) {
  char text[512];
  std::vsnprintf(text, sizeof text, message, arguments);
  throw Error("ode: internal error " + std::to_string(number) + ": " + text +
              " (the physics cannot go on; an object moved or grew to extreme values?)");
}

// Whether ODE's quickstep draws its constraint shuffles from the dRandInt
// defined below. Steps a small world once (a chain of three bodies, nine
// iterations, so that the rows are shuffled) and looks.
bool ProbeSolverShuffle() {
  dWorldID world = dWorldCreate();
  dThreadingImplementationID threading = dThreadingAllocateSelfThreadedImplementation();
  dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(threading),
                                       threading);
  dWorldSetQuickStepNumIterations(world, 9);
  dBodyID previous = nullptr;
  for (int i = 0; i < 3; ++i) {
    dBodyID body = dBodyCreate(world);
    dBodySetPosition(body, i, 0, 0);
    dJointID joint = dJointCreateBall(world, nullptr);
    dJointAttach(joint, body, previous);
    dJointSetBallAnchor(joint, i - 0.5, 0, 0);
    previous = body;
  }
  g_shuffle_called = false;
  dWorldQuickStep(world, 0.01);
  const bool ours = g_shuffle_called;
  dWorldSetStepThreadingImplementation(world, nullptr, nullptr);
  dWorldDestroy(world);
  dThreadingFreeImplementation(threading);
  return ours;
}

// ODE's message handler: ODE prints notes such as "LCP internal error, s <=
// 0" (its exact solver meeting a degenerate contact set) straight to stderr,
// one per step. Ours says the first once, as a warning with what to do.
void NoteOdeMessage(int number, const char* message, va_list arguments) {
  static std::atomic<bool> said{false};
  if (said.exchange(true)) return;
  char text[512];
  std::vsnprintf(text, sizeof text, message, arguments);
  std::fprintf(stderr,
               "warning: ode: message %d: %s (ODE's exact solver met a degenerate set of "
               "contacts; `simulation: {ode: {solver: quickstep}}` avoids it); further ODE "
               "messages are not shown\n",
               number, text);
}

// ODE's allocator: ODE writes through what malloc returned without a look
// in most places, so memory refused (ulimit -v, a large world on a small
// machine) was a segfault inside the library. A refusal throws
// std::bad_alloc instead, which unwinds out of ODE (C++, as ThrowOdeError's
// errors do) to the world's start or step: the run ends with a message.
void* AllocOrThrow(dsizeint size) {
  void* memory = std::malloc(size > 0 ? size : 1);
  if (memory == nullptr) throw std::bad_alloc();
  return memory;
}
void* ReallocOrThrow(void* memory, dsizeint, dsizeint size) {
  void* moved = std::realloc(memory, size > 0 ? size : 1);
  if (moved == nullptr) throw std::bad_alloc();
  return moved;
}
void FreeMemory(void* memory, dsizeint) { std::free(memory); }

bool g_solver_shuffle_is_ours = false;
bool g_single_threaded_islands = false;  // SolverThreads' probe

}  // namespace

void InitOdeOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    dSetAllocHandler(AllocOrThrow);  // before ODE allocates anything
    dSetReallocHandler(ReallocOrThrow);
    dSetFreeHandler(FreeMemory);
    dInitODE2(0);
    dSetErrorHandler(ThrowOdeError);
    dSetDebugHandler(ThrowOdeError);
    dSetMessageHandler(NoteOdeMessage);
    dAllocateODEDataForThread(dAllocateMaskAll);
    g_solver_shuffle_is_ours = ProbeSolverShuffle();
    if (g_solver_shuffle_is_ours)
      g_single_threaded_islands = SolverThreads::ProbeSingleThreadedIslands();
  });
}

bool SolverShuffleIsOurs() {
  InitOdeOnce();
  return g_solver_shuffle_is_ours;
}

std::string SolverThreading() {
  InitOdeOnce();
  if (!g_solver_shuffle_is_ours)
    return "the solver runs on one thread (ODE's dRandInt is not the program's)";
  if (!g_single_threaded_islands)
    return "islands solved concurrently on the run's threads (ODE's multi-threaded island path)";
  return "islands solved concurrently on the run's threads";
}

}  // namespace swarmsim::ode
