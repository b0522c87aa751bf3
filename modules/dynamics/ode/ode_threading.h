// The ODE solver's threads: a threading implementation (ODE's
// dThreadingFunctionsInfo) that steps ODE's islands (bodies linked by joints
// and contacts: a robot, or robots touching) concurrently while keeping each
// island's own work on one thread, so that a state is bit-identical for any
// thread count. Internal to the ODE module (ode_world.cc).
//
// Why not ODE's own thread pool: ODE 0.16 gives every island as many threads
// as it steps islands in parallel (util.cpp: "for now, set stepper allowed
// threads equal to island stepping threads"), and its multi-threaded
// quickstep then solves an island's constraint rows concurrently, each row
// waiting only for the last earlier row on one of its two bodies: the order
// of the updates to the other body depends on timing (different states at 3
// and 4 threads, and between two runs at 4, measured). That path also posts a
// few calls per solver iteration: for small islands (a 3-body wheeled robot)
// it cost more than the island's whole single-threaded solve. Here:
//   - each island is solved by ODE's single-threaded quickstep: before ODE
//     runs its "World Islands Stepping Start" calls, the threads it allows
//     one island's stepper (the last of the first members of ODE 0.16's
//     dxIslandsProcessingCallContext, which those calls carry: the world, the
//     islands, the step size, the stepper, the group releasee, the island
//     counter, then that count) are set to 1. The layout is checked (the
//     world and the count must be where they belong) and probed once per
//     process (ProbeSingleThreadedIslands); where it does not hold, ODE is
//     told of at least 2 threads at any thread count, so that it always takes
//     its multi-threaded path and results still do not depend on the count;
//   - a call posted from inside a call runs on the thread that posted it, so
//     an island's calls run one after another on one thread, in an order
//     fixed by the island alone;
//   - only calls posted from outside a call (ODE's top-level "stepping start"
//     calls, one per chain of islands) go to a queue every thread takes from.
// The threads are the run's (TaskScheduler): while the stepping thread waits
// for a step (WaitCall), it and the scheduler's workers each work from one
// queue ("lane") until the step is done. No threads of its own: on a 2-core
// machine a third thread would compete with the scheduler's.
//
// A call that throws (ODE's error handler throws: ode_world.cc) is caught on
// its thread; the calls after it are skipped and the step is reported failed,
// and the first exception is rethrown on the stepping thread (TakeFailure).
#pragma once

#include <ode/ode.h>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <mutex>
#include <vector>

namespace swarmsim {
class TaskScheduler;
}

namespace swarmsim::ode {

class SolverThreads {
 public:
  // The scheduler's threads (null: the stepping thread alone), stepping
  // `world`'s islands (set_world when it is rebuilt).
  SolverThreads(TaskScheduler* scheduler, dWorldID world);
  ~SolverThreads();
  SolverThreads(const SolverThreads&) = delete;
  SolverThreads& operator=(const SolverThreads&) = delete;

  // For dWorldSetStepThreadingImplementation.
  const dThreadingFunctionsInfo* functions() const { return &functions_; }
  dThreadingImplementationID id() { return reinterpret_cast<dThreadingImplementationID>(this); }

  void set_world(dWorldID world) { world_ = world; }
  // Seeds the constraint shuffles of the next step (DrawShuffle).
  void set_shuffle_seed(uint64_t seed) { shuffle_seed_ = seed; }

  // ODE's quickstep shuffles an island's constraint rows now and then with
  // dRandInt (ode_world.cc). While an island is solved on this thread (one
  // island per thread at a time, see above), its draws come from a stream
  // that starts at the step's seed for every island: the same draws whatever
  // thread solves it and whenever. Sets *out to a draw in [0, n) and returns
  // true, or returns false outside an island's solve.
  static bool DrawShuffle(int n, int* out);

  // The first exception a call threw during the last step, cleared (null if none).
  std::exception_ptr TakeFailure();

  // Whether ODE's islands can be given one thread each (see above): steps a
  // small world once and looks. Call once per process, before any other use.
  static bool ProbeSingleThreadedIslands();

  struct Job;
  struct Wait;

 private:
  static constexpr int kShared = -1;  // the queue every thread takes from

  void Post(int* out_fault, dCallReleaseeID* out_releasee, ddependencycount_t dependencies,
            dCallReleaseeID dependent, dCallWaitID wait, dThreadedCallFunction* fn, void* context,
            dcallindex_t index, const char* name);
  // The thread count ODE is told.
  unsigned Reported() const;
  // Gives the islands of the step ODE starts with `context` one thread each
  // (see above); false if ODE's layout is not the probed one.
  bool SingleThreadedIslands(void* context);
  void Alter(dCallReleaseeID releasee, ddependencychange_t change);
  void WaitCall(int* out_status, dCallWaitID wait, const dThreadedWaitTime* timeout);
  // Works from queue `lane` (and the shared one) until `wait` is done.
  void Lane(int lane, Wait* wait);
  // Runs `job` on this thread (unless a call failed this step) and releases
  // it; `lock` (on mutex_) is held on entry and on return, not while the
  // call runs.
  void Run(std::unique_lock<std::mutex>& lock, Job* job);
  // One dependency of `job` done (its own run, or a call it waits for): a
  // job with none left either starts (queued) or, if it ran, completes and
  // releases the job depending on it.
  void Release(Job* job, bool failed);
  void MakeReady(Job* job);  // lock held
  Job* NewJob();             // lock held
  Job* PopFor(int self);     // lock held
  void Signal(Wait* wait);

  TaskScheduler* scheduler_;
  dWorldID world_;
  uint64_t shuffle_seed_ = 0;
  int threads_;
  dThreadingFunctionsInfo functions_{};
  std::mutex mutex_;
  std::condition_variable work_;         // a queue got a job, a wait was signalled, or shutdown
  std::vector<std::deque<Job*>> local_;  // per thread: calls posted from its calls
  std::deque<Job*> shared_;
  std::vector<Job*> free_jobs_;
  std::exception_ptr failure_;
  bool failed_ = false;  // a call threw this step: skip the rest
};

}  // namespace swarmsim::ode
