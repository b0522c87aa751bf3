#include "modules/dynamics/ode/ode_threading.h"

#include <algorithm>
#include <cstring>
#include <memory>

#include "framework/error.h"
#include "framework/scheduler.h"
#include "modules/dynamics/ode/ode_internal.h"

namespace swarmsim::ode {

struct SolverThreads::Job {
  bool island = false;                  // the call that steps one whole island
  ddependencycount_t dependencies = 0;  // calls (and its own run) still to finish
  Job* dependent = nullptr;             // released when this one completes
  Wait* wait = nullptr;
  int* fault_out = nullptr;
  dThreadedCallFunction* fn = nullptr;
  void* context = nullptr;
  dcallindex_t index = 0;
  int home = kShared;    // the queue it runs from
  bool started = false;  // taken from its queue (ODE's "dequeued")
  bool fault = false;    // it or a call it waited for failed
};

struct SolverThreads::Wait {
  bool done = false;
};

namespace {

struct MutexGroup {
  std::unique_ptr<std::mutex[]> mutexes;
};

// The thread's place in a pool: which pool, its queue, and whether it is
// running one of the pool's calls (posts from a call stay on the thread).
thread_local SolverThreads* t_pool = nullptr;
thread_local int t_self = -1;
thread_local int t_in_call = 0;

SolverThreads* Self(dThreadingImplementationID impl) {
  return reinterpret_cast<SolverThreads*>(impl);
}

// The first members of ODE 0.16's dxIslandsProcessingCallContext (ode/src/util.cpp).
struct IslandsContextHead {
  dxWorld* world;
  const void* islands_info;  // a reference
  dReal step_size;
  void* stepper;
  dCallReleaseeID group_releasee;
  size_t island_to_process;
  unsigned stepper_allowed_threads;
};

constexpr char kIslandsStart[] = "World Islands Stepping Start";
// The call that steps one island: all of it, when islands have one thread.
constexpr char kIslandStepper[] = "Island Stepping Job Start";

// The shuffle stream of the island being solved on this thread.
thread_local bool t_shuffling = false;
thread_local uint64_t t_shuffle_state = 0;

// Set once per process (ProbeSingleThreadedIslands): islands get one thread each.
bool g_single_threaded_islands = false;

}  // namespace

SolverThreads::SolverThreads(TaskScheduler* scheduler, dWorldID world)
    : scheduler_(scheduler),
      world_(world),
      threads_(scheduler ? std::max(1, scheduler->threads()) : 1) {
  local_.resize(static_cast<size_t>(threads_));
  functions_.struct_size = sizeof(functions_);
  functions_.alloc_mutex_group = [](dThreadingImplementationID, dmutexindex_t count,
                                    const char* const*) -> dMutexGroupID {
    auto* group = new MutexGroup{std::make_unique<std::mutex[]>(count)};
    return reinterpret_cast<dMutexGroupID>(group);
  };
  functions_.free_mutex_group = [](dThreadingImplementationID, dMutexGroupID group) {
    delete reinterpret_cast<MutexGroup*>(group);
  };
  functions_.lock_group_mutex = [](dThreadingImplementationID, dMutexGroupID group,
                                   dmutexindex_t i) {
    reinterpret_cast<MutexGroup*>(group)->mutexes[i].lock();
  };
  functions_.unlock_group_mutex = [](dThreadingImplementationID, dMutexGroupID group,
                                     dmutexindex_t i) {
    reinterpret_cast<MutexGroup*>(group)->mutexes[i].unlock();
  };
  functions_.alloc_call_wait = [](dThreadingImplementationID) -> dCallWaitID {
    return reinterpret_cast<dCallWaitID>(new Wait);
  };
  functions_.reset_call_wait = [](dThreadingImplementationID impl, dCallWaitID wait) {
    std::lock_guard<std::mutex> lock(Self(impl)->mutex_);
    reinterpret_cast<Wait*>(wait)->done = false;
  };
  functions_.free_call_wait = [](dThreadingImplementationID, dCallWaitID wait) {
    delete reinterpret_cast<Wait*>(wait);
  };
  functions_.post_call = [](dThreadingImplementationID impl, int* out_fault,
                            dCallReleaseeID* out_releasee, ddependencycount_t dependencies,
                            dCallReleaseeID dependent, dCallWaitID wait, dThreadedCallFunction* fn,
                            void* context, dcallindex_t index, const char* name) {
    Self(impl)->Post(out_fault, out_releasee, dependencies, dependent, wait, fn, context, index,
                     name);
  };
  functions_.alter_call_dependencies_count =
      [](dThreadingImplementationID impl, dCallReleaseeID releasee, ddependencychange_t change) {
        Self(impl)->Alter(releasee, change);
      };
  functions_.wait_call = [](dThreadingImplementationID impl, int* out_status, dCallWaitID wait,
                            const dThreadedWaitTime* timeout,
                            const char*) { Self(impl)->WaitCall(out_status, wait, timeout); };
  functions_.retrieve_thread_count = [](dThreadingImplementationID impl) -> unsigned {
    return Self(impl)->Reported();
  };
  functions_.preallocate_resources_for_calls = [](dThreadingImplementationID,
                                                  ddependencycount_t) -> int { return 1; };
}

SolverThreads::~SolverThreads() {
  for (Job* job : free_jobs_) delete job;
  // Jobs still queued or waiting (a step unwound by an error) are leaked
  // with the ODE world that posted them.
}

std::exception_ptr SolverThreads::TakeFailure() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::exception_ptr failure = failure_;
  failure_ = nullptr;
  failed_ = false;
  return failure;
}

SolverThreads::Job* SolverThreads::NewJob() {
  if (free_jobs_.empty()) return new Job;
  Job* job = free_jobs_.back();
  free_jobs_.pop_back();
  *job = Job{};
  return job;
}

bool SolverThreads::DrawShuffle(int n, int* out) {
  if (!t_shuffling) return false;
  // splitmix64
  *out = Below(Mix64(t_shuffle_state += 0x9e3779b97f4a7c15ULL), n);
  return true;
}

unsigned SolverThreads::Reported() const {
  // Without one thread per island: at least 2, so that ODE always takes its
  // multi-threaded path (see the header).
  return static_cast<unsigned>(g_single_threaded_islands ? threads_ : std::max(2, threads_));
}

bool SolverThreads::SingleThreadedIslands(void* context) {
  auto* head = static_cast<IslandsContextHead*>(context);
  // One such call per chain of islands, all with this context: the first
  // finds ODE's count, the others the 1 it was given.
  if (head->world != reinterpret_cast<dxWorld*>(world_) ||
      (head->stepper_allowed_threads != Reported() && head->stepper_allowed_threads != 1))
    return false;
  head->stepper_allowed_threads = 1;
  return true;
}

bool SolverThreads::ProbeSingleThreadedIslands() {
  // Two separate bodies (two islands) hanging from the world by a ball joint
  // each, stepped once with 2 threads reported and the layout checked.
  dWorldID world = dWorldCreate();
  dWorldSetQuickStepNumIterations(world, 4);
  for (int i = 0; i < 2; ++i) {
    dBodyID body = dBodyCreate(world);
    dBodySetPosition(body, 2.0 * i, 0, 0);
    dJointID joint = dJointCreateBall(world, nullptr);
    dJointAttach(joint, body, nullptr);
    dJointSetBallAnchor(joint, 2.0 * i, 0, 1);
  }
  g_single_threaded_islands = true;
  bool ok = true;
  {
    SolverThreads probe(nullptr, world);
    probe.threads_ = 2;  // reported; the stepping thread does the work
    dWorldSetStepThreadingImplementation(world, probe.functions(), probe.id());
    ok = dWorldQuickStep(world, 0.01) != 0 && !probe.TakeFailure();
    dWorldSetStepThreadingImplementation(world, nullptr, nullptr);
  }
  dWorldDestroy(world);
  g_single_threaded_islands = ok;
  return ok;
}

void SolverThreads::Post(int* out_fault, dCallReleaseeID* out_releasee,
                         ddependencycount_t dependencies, dCallReleaseeID dependent,
                         dCallWaitID wait, dThreadedCallFunction* fn, void* context,
                         dcallindex_t index, const char* name) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (g_single_threaded_islands && name && std::strcmp(name, kIslandsStart) == 0 &&
      !SingleThreadedIslands(context) && !failed_) {
    // ODE went on with its multi-threaded islands: a result the other thread
    // counts would not give. The step is reported failed (TakeFailure).
    failure_ = std::make_exception_ptr(
        Error("ode: the solver's island threads are not where ODE 0.16 keeps them"));
    failed_ = true;
  }
  Job* job = NewJob();
  job->dependencies = dependencies;
  job->dependent = reinterpret_cast<Job*>(dependent);
  job->wait = reinterpret_cast<Wait*>(wait);
  job->fault_out = out_fault;
  job->fn = fn;
  job->context = context;
  job->index = index;
  job->island = g_single_threaded_islands && name && std::strcmp(name, kIslandStepper) == 0;
  job->home = t_pool == this && t_in_call > 0 ? t_self : kShared;
  if (out_releasee) *out_releasee = reinterpret_cast<dCallReleaseeID>(job);
  if (dependencies == 0) MakeReady(job);
}

void SolverThreads::MakeReady(Job* job) {
  if (job->home == kShared) {
    shared_.push_back(job);
  } else {
    local_[static_cast<size_t>(job->home)].push_back(job);
  }
  // The thread itself will find it; any other may be asleep.
  if (!(t_pool == this && job->home == t_self)) work_.notify_all();
}

void SolverThreads::Alter(dCallReleaseeID releasee, ddependencychange_t change) {
  std::lock_guard<std::mutex> lock(mutex_);
  Job* job = reinterpret_cast<Job*>(releasee);
  job->dependencies =
      static_cast<ddependencycount_t>(static_cast<ddependencychange_t>(job->dependencies) + change);
  if (job->dependencies != 0) return;
  if (!job->started) {
    MakeReady(job);
    return;
  }
  // A call that ran and then waited for calls it added: they are all done.
  job->dependencies = 1;
  Release(job, false);
}

void SolverThreads::Release(Job* job, bool failed) {
  if (failed) job->fault = true;
  while (job) {
    if (--job->dependencies != 0) return;
    if (!job->started) {
      MakeReady(job);
      return;
    }
    if (job->wait) Signal(job->wait);
    if (job->fault_out) *job->fault_out = job->fault ? 1 : 0;
    Job* dependent = job->dependent;
    if (dependent && job->fault) dependent->fault = true;
    free_jobs_.push_back(job);
    job = dependent;
  }
}

void SolverThreads::Signal(Wait* wait) {
  wait->done = true;
  work_.notify_all();
}

SolverThreads::Job* SolverThreads::PopFor(int self) {
  std::deque<Job*>* queue = &local_[static_cast<size_t>(self)];
  if (queue->empty()) queue = &shared_;
  if (queue->empty()) return nullptr;
  Job* job = queue->front();
  queue->pop_front();
  job->started = true;
  job->dependencies = 1;  // its own run
  return job;
}

void SolverThreads::Run(std::unique_lock<std::mutex>& lock, Job* job) {
  bool ok = false;
  if (!failed_) {
    lock.unlock();
    ++t_in_call;
    if (job->island) {
      t_shuffling = true;
      t_shuffle_state = shuffle_seed_;
    }
    std::exception_ptr thrown;
    try {
      ok = job->fn(job->context, job->index, reinterpret_cast<dCallReleaseeID>(job)) != 0;
    } catch (...) {
      thrown = std::current_exception();
    }
    t_shuffling = false;
    --t_in_call;
    lock.lock();
    if (thrown) {
      if (!failure_) failure_ = thrown;
      failed_ = true;
    }
  }
  Release(job, !ok);
}

void SolverThreads::Lane(int lane, Wait* wait) {
  SolverThreads* const saved_pool = t_pool;
  const int saved_self = t_self;
  t_pool = this;
  t_self = lane;
  dAllocateODEDataForThread(dAllocateMaskAll);
  std::unique_lock<std::mutex> lock(mutex_);
  while (!wait->done) {
    if (Job* job = PopFor(lane)) {
      Run(lock, job);
      continue;
    }
    work_.wait(lock);
  }
  lock.unlock();
  t_pool = saved_pool;
  t_self = saved_self;
}

void SolverThreads::WaitCall(int* out_status, dCallWaitID wait_id,
                             const dThreadedWaitTime* timeout) {
  Wait* wait = reinterpret_cast<Wait*>(wait_id);
  const bool poll = timeout && timeout->wait_sec == 0 && timeout->wait_nsec == 0;
  if (!poll) {
    if (scheduler_ && threads_ > 1) {
      // One lane per thread; a lane that starts late finds the step done.
      scheduler_->ParallelFor(0, threads_, 1, [this, wait](int64_t begin, int64_t end) {
        for (int64_t lane = begin; lane < end; ++lane) Lane(static_cast<int>(lane), wait);
      });
    } else {
      Lane(0, wait);
    }
  }
  if (out_status) {
    std::lock_guard<std::mutex> lock(mutex_);
    *out_status = wait->done ? 1 : 0;
  }
}

}  // namespace swarmsim::ode
