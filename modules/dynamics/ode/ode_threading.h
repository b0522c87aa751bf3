// The ODE solver's threads: a threading implementation (ODE's
// dThreadingFunctionsInfo) that steps ODE's islands (bodies linked by joints
// and contacts: a robot, or robots touching) concurrently while keeping each
// island's own work on one thread, so that a state is bit-identical for any
// thread count. Internal to the ODE module (ode_world.cc).
//
// Why not ODE's own thread pool: ODE 0.16 gives every island as many threads
// as it steps islands in parallel, and its multi-threaded quickstep then
// solves an island's constraint rows concurrently, each row waiting only for
// the last earlier row on one of its two bodies: the order of the updates to
// the other body depends on timing (different states at 3 and 4 threads, and
// between two runs at 4, measured). Here:
//   - thread_count() is what ODE is told, at least 2, so that ODE always takes
//     its multi-threaded code path (whose result differs from its
//     single-threaded one), whatever the real number of threads;
//   - a call posted from inside a call runs on the thread that posted it, so
//     an island's calls (each island is stepped by one chain of calls) run one
//     after another on one thread, in an order fixed by the island alone;
//   - only calls posted from outside a call (ODE's top-level "stepping start"
//     calls, one per chain) go to a queue that every thread takes from.
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
  // The scheduler's threads (null: the stepping thread alone).
  explicit SolverThreads(TaskScheduler* scheduler);
  ~SolverThreads();
  SolverThreads(const SolverThreads&) = delete;
  SolverThreads& operator=(const SolverThreads&) = delete;

  // For dWorldSetStepThreadingImplementation.
  const dThreadingFunctionsInfo* functions() const { return &functions_; }
  dThreadingImplementationID id() { return reinterpret_cast<dThreadingImplementationID>(this); }

  // The first exception a call threw during the last step, cleared (null if none).
  std::exception_ptr TakeFailure();

  struct Job;
  struct Wait;

 private:
  static constexpr int kShared = -1;  // the queue every thread takes from

  void Post(int* out_fault, dCallReleaseeID* out_releasee, ddependencycount_t dependencies,
            dCallReleaseeID dependent, dCallWaitID wait, dThreadedCallFunction* fn, void* context,
            dcallindex_t index);
  void Alter(dCallReleaseeID releasee, ddependencychange_t change);
  void WaitCall(int* out_status, dCallWaitID wait, const dThreadedWaitTime* timeout);
  // Works from queue `lane` (and the shared one) until `wait` is done.
  void Lane(int lane, Wait* wait);
  // Runs `job` on this thread and releases it.
  void Run(Job* job);
  // One dependency of `job` done (its own run, or a call it waits for): a
  // job with none left either starts (queued) or, if it ran, completes and
  // releases the job depending on it.
  void Release(Job* job, bool failed);
  void MakeReady(Job* job);  // lock held
  Job* NewJob();             // lock held
  Job* PopFor(int self);     // lock held
  void Signal(Wait* wait);

  TaskScheduler* scheduler_;
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
