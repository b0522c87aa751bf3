/* The host glue of a Kilobot program's plugin (framework/plugin_api.h,
 * ABI 8): registers one native controller that runs the program on every
 * robot of a models entry (`native_controller: NAME`).
 *
 * Per-robot globals. The build renamed the writable sections of the
 * program's and kilolib.c's objects to kilo_data and kilo_bss; this file is
 * not renamed. Each robot keeps an image of those two regions; before
 * calling into the program the host copies the robot's image in, after the
 * call it copies it back out. A region holds pointers into its own copy of
 * the library (a function pointer, the address of a global), so a robot
 * always runs on the same copy: the plugin loads K private copies of its
 * own file (robot r runs on copy (r / 64) % K, under that copy's lock), so
 * K robots run at once.
 *
 * Faults. A SIGSEGV, SIGBUS, SIGFPE, SIGILL or SIGABRT raised while a
 * thread runs the program's code (a thread-local flag says so) jumps back
 * here (siglongjmp) and the robot's step fails with a message naming the
 * robot and the program; a fault anywhere else keeps its usual effect.
 * Handlers run on a per-thread alternate stack, so a stack overflow is
 * caught too. A watchdog thread interrupts (pthread_kill) a call into the
 * program that has not returned within program_timeout seconds.
 *
 * KILOBOT_NAME (the controller's name) and KILOBOT_SOURCE (the program's
 * path) come from the build command. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <setjmp.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <ucontext.h>
#include <unistd.h>

#include "framework/plugin_api.h"
#include "kilobot_runtime.h"

#ifndef KILOBOT_NAME
#define KILOBOT_NAME "kilobot"
#endif
#ifndef KILOBOT_SOURCE
#define KILOBOT_SOURCE "kilobot.c"
#endif
#ifndef KILOBOT_DELAY /* the program calls delay() (the build says so) */
#define KILOBOT_DELAY 0
#endif

void kilobot_fill_copy(kilobot_copy_t *c); /* kilolib.c */

/* ---- this copy's table (every copy exports it) ---- */

__attribute__((visibility("default"))) const kilobot_copy_t *swarmsim_kilobot_copy(void) {
  static kilobot_copy_t table;
  static int filled;
  if (!filled) kilobot_fill_copy(&table), filled = 1;
  return &table;
}

/* ---- the copies (state of the copy swarmsim loaded) ---- */

enum { kMaxCopies = 64, kBlock = 64, kMaxMessages = 32 };

typedef struct {
  const kilobot_copy_t *table;
  char *region;   /* its kilo_data: the program's and kilolib.c's writable data */
  char *pristine; /* the region as loaded */
  size_t size;
  atomic_flag lock; /* held while a robot's regions are in (contention is rare) */
} Copy;

static Copy g_copies[kMaxCopies];
static int g_copy_count;
static char g_load_error[4096];

/* Loads a private copy of the file at `path`: copied to a temporary file,
 * opened, unlinked (so that the dynamic loader sees a new library). */
static const kilobot_copy_t *LoadCopy(const char *path) {
  const char *folder = getenv("TMPDIR");
  char temp[1024];
  snprintf(temp, sizeof temp, "%s/swarmsim-kilobot-XXXXXX.so",
           folder != NULL && folder[0] != 0 ? folder : "/tmp");
  int out = mkstemps(temp, 3);
  if (out < 0) {
    snprintf(g_load_error, sizeof g_load_error, "cannot create %s: %s", temp, strerror(errno));
    return NULL;
  }
  int in = open(path, O_RDONLY | O_CLOEXEC);
  int ok = in >= 0;
  char buffer[65536];
  ssize_t n = 0;
  while (ok && (n = read(in, buffer, sizeof buffer)) > 0) ok = write(out, buffer, (size_t)n) == n;
  ok = ok && n == 0;
  if (in >= 0) close(in);
  close(out);
  void *handle = ok ? dlopen(temp, RTLD_NOW | RTLD_LOCAL) : NULL;
  if (!ok)
    snprintf(g_load_error, sizeof g_load_error, "cannot copy %s to %s", path, temp);
  else if (handle == NULL)
    snprintf(g_load_error, sizeof g_load_error, "cannot load a copy of %s: %s", path, dlerror());
  unlink(temp);
  if (handle == NULL) return NULL;
  const kilobot_copy_t *(*entry)(void) =
      (const kilobot_copy_t *(*)(void))dlsym(handle, "swarmsim_kilobot_copy");
  if (entry == NULL) {
    snprintf(g_load_error, sizeof g_load_error, "a copy of %s has no swarmsim_kilobot_copy", path);
    return NULL;
  }
  return entry();
}

static int AddCopy(const kilobot_copy_t *table) {
  Copy *c = &g_copies[g_copy_count];
  c->table = table;
  c->region = table->data_begin;
  c->size = (size_t)(table->data_end - table->data_begin);
  c->pristine = malloc(c->size + 1);
  if (c->pristine == NULL) return -1;
  memcpy(c->pristine, c->region, c->size);
  atomic_flag_clear(&c->lock);
  ++g_copy_count;
  return 0;
}

/* Copy 0 is this one; the others are loaded from this file. */
static int LoadCopies(void) {
  long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  int wanted = cpus > 0 ? (int)(8 * cpus) : 8;
  const char *env = getenv("SWARMSIM_KILOBOT_COPIES");
  if (env != NULL && atoi(env) > 0) wanted = atoi(env);
  if (wanted > kMaxCopies) wanted = kMaxCopies;
  if (AddCopy(swarmsim_kilobot_copy()) != 0) return -1;
  Dl_info info;
  if (dladdr((void *)&LoadCopies, &info) == 0 || info.dli_fname == NULL) return 0;
  while (g_copy_count < wanted) {
    const kilobot_copy_t *table = LoadCopy(info.dli_fname);
    if (table == NULL) break; /* fewer copies: fewer robots at once */
    if (AddCopy(table) != 0) break;
  }
  return 0;
}

static void Lock(Copy *c) {
  while (atomic_flag_test_and_set_explicit(&c->lock, memory_order_acquire)) sched_yield();
}
static void Unlock(Copy *c) { atomic_flag_clear_explicit(&c->lock, memory_order_release); }

/* The copy robot `robot` runs on: its block of kBlock robots, hashed, so
 * that two workers on two contiguous ranges that meet on one copy part at
 * the next block instead of going on in step. */
static int CopyOf(int robot) {
  uint32_t block = (uint32_t)robot / kBlock;
  block ^= block >> 16;
  block *= 0x7feb352dU;
  block ^= block >> 15;
  block *= 0x846ca68bU;
  block ^= block >> 16;
  return (int)(block % (uint32_t)g_copy_count);
}

/* ---- faults and the watchdog ---- */

typedef struct {
  pthread_t thread;
  atomic_ulong calls; /* calls into the program begun */
  atomic_int busy;    /* in the program now */
  atomic_int expired; /* the watchdog interrupted it */
} Slot;

enum { kMaxSlots = 512 };
static Slot g_slots[kMaxSlots];
static atomic_int g_slot_count;
static atomic_int g_timeout_ms; /* 0: no watchdog */
static pthread_once_t g_signals_once = PTHREAD_ONCE_INIT;
static pthread_once_t g_watchdog_once = PTHREAD_ONCE_INIT;
static struct sigaction g_old_actions[65];
static int g_watchdog_signal;
static const int kFaultSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};

/* Per thread, in one block (one TLS lookup in a loaded library). */
typedef struct {
  sigjmp_buf *jump;              /* where a fault in the program returns to */
  volatile sig_atomic_t in_user; /* the thread runs the program's code */
  Slot *slot;
  char *stack_low; /* lowest address of the thread's stack */
  volatile void *fault_address;
  int exit_status; /* the program called exit(exit_status) */
  const char *refused; /* the function it called that it may not (kCalledRefused) */
} ThreadState;
static __thread ThreadState t_state;
static Slot g_spare_slot; /* threads past kMaxSlots: no watchdog */

static void OnSignal(int sig, siginfo_t *info, void *context) {
  ThreadState *ts = &t_state;
  if (ts->in_user && ts->jump != NULL) {
    if (sig == g_watchdog_signal && (ts->slot == NULL || !atomic_load(&ts->slot->expired))) return;
    ts->in_user = 0;
    ts->fault_address = info != NULL ? info->si_addr : NULL;
    siglongjmp(*ts->jump, sig);
  }
  if (sig == g_watchdog_signal) return; /* the call returned meanwhile */
  /* Not the program's: what would have happened without us. */
  const struct sigaction *old = &g_old_actions[sig];
  if ((old->sa_flags & SA_SIGINFO) != 0 && old->sa_sigaction != NULL) {
    old->sa_sigaction(sig, info, context);
    return;
  }
  if (old->sa_handler != SIG_DFL && old->sa_handler != SIG_IGN && old->sa_handler != NULL) {
    old->sa_handler(sig);
    return;
  }
  signal(sig, SIG_DFL);
  raise(sig);
}

static void InstallHandlers(void) {
  g_watchdog_signal = SIGRTMIN + 5;
  struct sigaction action;
  memset(&action, 0, sizeof action);
  action.sa_sigaction = OnSignal;
  /* SA_NODEFER: the signal stays unblocked after the jump (sigsetjmp saves
   * no mask: that would cost a system call per call). */
  action.sa_flags = SA_SIGINFO | SA_ONSTACK | SA_NODEFER;
  sigemptyset(&action.sa_mask);
  for (size_t i = 0; i < sizeof kFaultSignals / sizeof kFaultSignals[0]; ++i)
    sigaction(kFaultSignals[i], &action, &g_old_actions[kFaultSignals[i]]);
  sigaction(g_watchdog_signal, &action, &g_old_actions[g_watchdog_signal]);
}

/* Once per thread: an alternate signal stack (a stack overflow's handler
 * needs one), the thread's stack bounds, a watchdog slot. */
static void SetUpThread(ThreadState *ts) {
  stack_t current;
  if (sigaltstack(NULL, &current) == 0 && (current.ss_flags & SS_DISABLE) != 0) {
    stack_t alternate;
    alternate.ss_size = 65536;
    alternate.ss_sp = malloc(alternate.ss_size);
    alternate.ss_flags = 0;
    if (alternate.ss_sp != NULL) sigaltstack(&alternate, NULL);
  }
  pthread_attr_t attr;
  if (pthread_getattr_np(pthread_self(), &attr) == 0) {
    void *low;
    size_t size;
    if (pthread_attr_getstack(&attr, &low, &size) == 0) ts->stack_low = low;
    pthread_attr_destroy(&attr);
  }
  const int index = atomic_fetch_add(&g_slot_count, 1);
  ts->slot = index < kMaxSlots ? &g_slots[index] : &g_spare_slot;
  ts->slot->thread = pthread_self();
}

static void *Watchdog(void *unused) {
  (void)unused;
  unsigned long seen[kMaxSlots] = {0};
  long stuck_ms[kMaxSlots] = {0};
  for (;;) {
    const int timeout = atomic_load(&g_timeout_ms);
    const long period_ms = timeout > 0 && timeout < 400 ? timeout / 4 + 1 : 100;
    struct timespec pause = {period_ms / 1000, (period_ms % 1000) * 1000000L};
    nanosleep(&pause, NULL);
    if (timeout <= 0) continue;
    const int count = atomic_load(&g_slot_count);
    for (int i = 0; i < count && i < kMaxSlots; ++i) {
      Slot *s = &g_slots[i];
      const unsigned long calls = atomic_load(&s->calls);
      if (!atomic_load(&s->busy) || calls != seen[i]) {
        seen[i] = calls, stuck_ms[i] = 0;
        continue;
      }
      stuck_ms[i] += period_ms;
      if (stuck_ms[i] >= timeout) {
        stuck_ms[i] = 0;
        atomic_store(&s->expired, 1);
        pthread_kill(s->thread, g_watchdog_signal);
      }
    }
  }
  return NULL;
}

static void StartWatchdog(void) {
  pthread_t thread;
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
  sigset_t all, old;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &old); /* the watchdog takes no signals */
  pthread_create(&thread, &attr, Watchdog, NULL);
  pthread_sigmask(SIG_SETMASK, &old, NULL);
  pthread_attr_destroy(&attr);
}

/* What Guarded returns when the program called exit() (not a signal). */
enum { kCalledExit = 4096, kCalledRefused = 4097 };

/* The program's exit() (the build renames its calls): ends the robot's
 * call like a fault, so the run ends naming the robot, not swarmsim. */
void kilobot_exit(int status) {
  ThreadState *ts = &t_state;
  if (ts->in_user && ts->jump != NULL) {
    ts->in_user = 0;
    ts->exit_status = status;
    siglongjmp(*ts->jump, kCalledExit);
  }
  exit(status);
}

/* The program's signal() and sigaction() (the build renames its calls):
 * avr-libc has neither, and here a handler would be the whole process's
 * (a SIGSEGV reset to the default killed swarmsim and left summary.json
 * "running"; SIGINT's would take Ctrl-C): the run ends naming the call. */
static void Refuse(const char *what) {
  ThreadState *ts = &t_state;
  if (ts->in_user && ts->jump != NULL) {
    ts->in_user = 0;
    ts->refused = what;
    siglongjmp(*ts->jump, kCalledRefused);
  }
}
typedef void (*Handler)(int);
static Handler RefuseSignal(const char *what) {
  Refuse(what);
  errno = EINVAL;
  return SIG_ERR;
}
Handler kilobot_signal(int sig, Handler h) { return (void)sig, (void)h, RefuseSignal("signal()"); }
Handler kilobot_bsd_signal(int sig, Handler h) { return (void)sig, (void)h, RefuseSignal("signal()"); }
Handler kilobot_sysv_signal(int sig, Handler h) { return (void)sig, (void)h, RefuseSignal("signal()"); }
Handler kilobot___sysv_signal(int sig, Handler h) {
  return (void)sig, (void)h, RefuseSignal("signal()");
}
Handler kilobot_sigset(int sig, Handler h) { return (void)sig, (void)h, RefuseSignal("sigset()"); }
int kilobot_sigaction(int sig, const struct sigaction *act, struct sigaction *old) {
  (void)sig, (void)act, (void)old;
  Refuse("sigaction()");
  errno = EINVAL;
  return -1;
}

/* The step (its time, in microseconds) at which a call timed out: the
 * other robots skip that step's calls, so that a program stuck on every
 * robot ends the run after one timeout instead of one per robot. */
static atomic_llong g_timed_out_at = -1;
/* The robot whose main() timed out (-1: none): the others' main() is not
 * called, for the same reason (it cost one timeout per robot: 25 minutes
 * for 300 robots). Both are the world's whose program hung (a process may
 * hold several, from Python), and a world's load clears them. */
static atomic_int g_main_timed_out = -1;
static _Atomic(void *) g_hung_world = NULL;

/* ---- delay(): the program on a stack of the robot's own ----
 *
 * A program that calls delay() (the build looks for the call) runs setup()
 * and loop() on a coroutine: delay(ms) notes when to wake and switches back
 * to the host, which returns from the robot's step; the steps until then
 * only deliver messages (kilolib's interrupts go on during a delay) and
 * transmissions; the step at which the time has come switches back into
 * the program, right after its delay() call. Its locals live on its stack,
 * its globals are swapped in and out as for every call. Programs without
 * delay() call setup() and loop() directly (no switch, no stack). */

typedef struct {
  ucontext_t self, back;       /* the program's context; the host's while it runs */
  const kilobot_copy_t *table; /* its copy's */
  char *map;                   /* the stack's mapping: a guard page, then the stack */
  size_t map_size;
  double wake;  /* s: simulated time delay() waits for (0: not waiting) */
  int in_setup; /* in setup() (for messages) */
  int waited;   /* the current loop() has called delay() */
} Coroutine;

enum { kStackSize = 64 * 1024 };
static __thread Coroutine *t_coroutine; /* the one running on this thread */
static __thread double t_now;           /* s: the step's time, for delay() */

static void CoroutineBody(void) {
  Coroutine *const co = t_coroutine;
  co->in_setup = 1;
  if (co->table->robot->setup != NULL) co->table->robot->setup();
  co->in_setup = 0;
  /* A loop() that ran straight through ends the robot's step (one loop()
   * a step); one that waited in delay() is followed at once by the next, as
   * on a Kilobot, in the step its wait ended. */
  for (;;) {
    co->waited = 0;
    if (co->table->robot->loop != NULL) co->table->robot->loop();
    if (!co->waited) swapcontext(&co->self, &co->back);
  }
}

static Coroutine *NewCoroutine(const kilobot_copy_t *table) {
  Coroutine *co = calloc(1, sizeof *co);
  if (co == NULL) return NULL;
  const size_t page = (size_t)sysconf(_SC_PAGESIZE);
  co->map_size = kStackSize + page;
  co->map = mmap(NULL, co->map_size, PROT_READ | PROT_WRITE,
                 MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (co->map == MAP_FAILED) {
    free(co);
    return NULL;
  }
  mprotect(co->map, page, PROT_NONE); /* a stack overflow faults here */
  co->table = table;
  getcontext(&co->self);
  co->self.uc_stack.ss_sp = co->map + page;
  co->self.uc_stack.ss_size = kStackSize;
  co->self.uc_link = NULL;
  makecontext(&co->self, CoroutineBody, 0);
  return co;
}

static void FreeCoroutine(Coroutine *co) {
  if (co == NULL) return;
  munmap(co->map, co->map_size);
  free(co);
}

void kilobot_wait(uint16_t ms) {
  Coroutine *const co = t_coroutine;
  if (co == NULL || ms == 0) return; /* main() or a callback: nothing to suspend */
  co->waited = 1;
  co->wake = t_now + ms / 1000.0;
  swapcontext(&co->self, &co->back);
}

/* ---- one call into the program ---- */

enum CallKind { kMain, kVoid, kRx, kTx, kResume };

typedef struct {
  enum CallKind kind;
  int (*main)(void);
  void (*void_fn)(void);
  message_rx_t rx;
  message_tx_t tx;
  message_t *message;
  distance_measurement_t *distance;
  message_t *result;
  Coroutine *coroutine;
} Call;

/* Runs `call`; returns 0, or the signal that ended it. */
static int Guarded(Call *call) {
  ThreadState *const ts = &t_state;
  if (ts->slot == NULL) SetUpThread(ts);
  sigjmp_buf jump;
  sigjmp_buf *const outer = ts->jump;
  const int sig = sigsetjmp(jump, 0);
  if (sig != 0) {
    atomic_store_explicit(&ts->slot->busy, 0, memory_order_relaxed);
    ts->jump = outer;
    t_coroutine = NULL;
    return sig;
  }
  ts->jump = &jump;
  Slot *const slot = ts->slot;
  /* Relaxed: only this thread writes them; the watchdog needs them only
   * eventually (it looks every 100 ms). */
  atomic_store_explicit(&slot->expired, 0, memory_order_relaxed);
  atomic_store_explicit(&slot->calls, atomic_load_explicit(&slot->calls, memory_order_relaxed) + 1,
                        memory_order_relaxed);
  atomic_store_explicit(&slot->busy, 1, memory_order_relaxed);
  ts->in_user = 1;
  switch (call->kind) {
    case kMain: call->main(); break;
    case kVoid: call->void_fn(); break;
    case kRx: call->rx(call->message, call->distance); break;
    case kTx: call->result = call->tx(); break;
    case kResume:
      t_coroutine = call->coroutine;
      swapcontext(&call->coroutine->back, &call->coroutine->self);
      t_coroutine = NULL;
      break;
  }
  ts->in_user = 0;
  atomic_store_explicit(&slot->busy, 0, memory_order_relaxed);
  ts->jump = outer;
  return 0;
}

/* ---- one robot ---- */

typedef struct {
  int copy;
  char *image;                  /* its region (right after this struct) */
  int64_t left, right;          /* ./leftMotor, ./rightMotor */
  int64_t led, light, ir;       /* 0: none */
  double true_left, true_right; /* duty cycles giving forward_speed */
  double speed, leg_radius, stall;
  double ambient_scale;
  int16_t voltage, temperature;
  int crc_check;
  double tx_clock;        /* clock cycles since the last transmission */
  double tx_wait;         /* cycles of back-off left */
  uint64_t backoff_state; /* the back-off's generator (an LCG) */
  int tx_pending;         /* a message was queued last step */
  double last_time;
  int set_up;                             /* setup() ran */
  uint8_t motor_left, motor_right, color; /* as last applied */
  int motors_applied, color_applied;
  Coroutine *coroutine; /* programs that call delay(): their stack (null until the first step) */
} Robot;

static atomic_int g_warned_crc;

static double Param(const SwarmsimCallContext *c, const char *name, double fallback) {
  double value = fallback;
  c->api->number_parameter(c->world, c->robot, name, &value);
  return value;
}

static int64_t Find(const SwarmsimCallContext *c, const char *path) {
  int64_t object = 0;
  return c->api->find_object(c->world, c->script_object, path, &object) ? object : 0;
}

/* A few hundred bytes: a word loop beats a call to memcpy. */
static inline void CopyBytes(char *to, const char *from, size_t size) {
  size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    uint64_t word;
    __builtin_memcpy(&word, from + i, 8);
    __builtin_memcpy(to + i, &word, 8);
  }
  for (; i < size; ++i) to[i] = from[i];
}
static void SwapIn(const Copy *c, const Robot *r) { CopyBytes(c->region, r->image, c->size); }
static void SwapOut(const Copy *c, Robot *r) { CopyBytes(r->image, c->region, c->size); }

static const char *SignalText(int sig) {
  if (sig == SIGSEGV) return "segmentation fault";
  if (sig == SIGBUS) return "bus error";
  if (sig == SIGFPE) return "arithmetic exception (e.g. an integer division by zero)";
  if (sig == SIGILL) return "illegal instruction";
  if (sig == SIGABRT) return "abort() called";
  return "signal";
}

static void Failure(const SwarmsimCallContext *c, int sig, const char *what, char *error,
                    size_t size, const Coroutine *co) {
  if (sig == kCalledRefused) {
    snprintf(error, size,
             "%s (kilobot program '%s'), robot %d: %s called in %s: a Kilobot program may not "
             "handle signals (avr-libc has no signal(); here its handler would be swarmsim's)",
             KILOBOT_SOURCE, KILOBOT_NAME, c->robot, t_state.refused, what);
    return;
  }
  if (sig == kCalledExit) {
    snprintf(error, size, "%s (kilobot program '%s'), robot %d: exit(%d) called in %s",
             KILOBOT_SOURCE, KILOBOT_NAME, c->robot, t_state.exit_status, what);
    return;
  }
  if (sig == g_watchdog_signal) {
    snprintf(error, size, "%s (kilobot program '%s'), robot %d: %s did not return within %g s",
             KILOBOT_SOURCE, KILOBOT_NAME, c->robot, what, atomic_load(&g_timeout_ms) / 1000.0);
    return;
  }
  const ThreadState *ts = &t_state;
  const char *address = (const char *)ts->fault_address;
  int overflow = sig == SIGSEGV && ts->stack_low != NULL && address != NULL &&
                 address < ts->stack_low + 65536 && address + 65536 * 16 > ts->stack_low;
  /* The coroutine's guard page, or below it: a large local array jumps
     past the guard page (up to 1 MiB counted as the stack's). */
  const uintptr_t at = (uintptr_t)address, guard = (uintptr_t)(co != NULL ? co->map : NULL);
  if (co != NULL && sig == SIGSEGV && address != NULL && at < guard + (co->map_size - kStackSize) &&
      at + (1u << 20) > guard)
    overflow = 1;
  snprintf(error, size, "%s (kilobot program '%s'), robot %d: %s%s in %s", KILOBOT_SOURCE,
           KILOBOT_NAME, c->robot, SignalText(sig), overflow ? " (stack overflow)" : "", what);
}

/* kilolib's timer: 8 MHz / 1024 (kilolib.c: kilo_tx_period 3906 = 0.5 s). */
static const double kCyclesPerSecond = 8e6 / 1024;

static void ApplyOutputs(const SwarmsimCallContext *c, Robot *r, const kilobot_robot_t *rt) {
  if (!r->motors_applied || rt->motor_left != r->motor_left || rt->motor_right != r->motor_right) {
    r->motor_left = rt->motor_left, r->motor_right = rt->motor_right, r->motors_applied = 1;
    const double left = r->motor_left < r->stall ? 0 : r->speed * r->motor_left / r->true_left;
    const double right = r->motor_right < r->stall ? 0 : r->speed * r->motor_right / r->true_right;
    c->api->set_joint_target_velocity(c->world, c->robot, r->left, left / r->leg_radius);
    c->api->set_joint_target_velocity(c->world, c->robot, r->right, right / r->leg_radius);
  }
  if (r->led != 0 && (!r->color_applied || rt->color != r->color)) {
    r->color = rt->color, r->color_applied = 1;
    const int red = r->color & 3, green = (r->color >> 2) & 3, blue = (r->color >> 4) & 3;
    if (c->api->set_led(c->world, c->robot, r->led, red / 3.0, green / 3.0, blue / 3.0,
                        r->color != 0) != 0)
      r->led = 0; /* no LED (or not one of this robot's): colours go nowhere */
  }
}

static int Init(const SwarmsimCallContext *c, void **state, char *error, size_t error_size,
                void *unused) {
  (void)unused;
  if (g_copy_count == 0) {
    snprintf(error, error_size, "the plugin could not load its program: %s", g_load_error);
    return -1;
  }
  const int copy_index = CopyOf(c->robot);
  Copy *copy = &g_copies[copy_index];
  /* The robot's host state and its image in one block: fewer cache lines. */
  const size_t head = (sizeof(Robot) + 63) / 64 * 64;
  Robot *r = aligned_alloc(64, head + (copy->size + 63) / 64 * 64);
  if (r == NULL) {
    snprintf(error, error_size, "out of memory");
    return -1;
  }
  memset(r, 0, sizeof *r);
  *state = r;
  r->copy = copy_index;
  r->image = (char *)r + head;
  memcpy(r->image, copy->pristine, copy->size);
  r->left = Find(c, "./leftMotor");
  r->right = Find(c, "./rightMotor");
  if (r->left == 0 || r->right == 0) {
    snprintf(error, error_size,
             "the robot has no ./leftMotor and ./rightMotor joints (worlds/models/kilobot.yaml)");
    return -1;
  }
  r->led = Find(c, "./led");
  r->light = Find(c, "./light");
  r->ir = Find(c, "./ir");
  /* Parameters (worlds/models/kilobot.yaml documents them). */
  r->speed = Param(c, "forward_speed", 0.01);
  r->leg_radius = Param(c, "leg_radius", 0.002);
  r->stall = Param(c, "stall_duty", 26);
  r->ambient_scale = Param(c, "ambient_scale", 100);
  r->voltage = (int16_t)Param(c, "voltage_adc", 700);
  r->temperature = (int16_t)Param(c, "temperature_adc", 292);
  r->crc_check = Param(c, "crc_check", 1) != 0;
  const double nominal = Param(c, "nominal_duty", 70);
  const double spread = Param(c, "duty_spread", 0.1);
  const double calibration_error = Param(c, "calibration_error", 0);
  const int timeout_ms = (int)(Param(c, "program_timeout", 5) * 1000);
  if (timeout_ms > 0) {
    int expected = 0;
    atomic_compare_exchange_strong(&g_timeout_ms, &expected, timeout_ms);
    pthread_once(&g_watchdog_once, StartWatchdog);
  }
  /* The robot's true calibration, drawn once from its random stream. */
  double (*uniform)(void *, int) = c->api->random_uniform;
  r->true_left = nominal * (1 + spread * (2 * uniform(c->world, c->robot) - 1));
  r->true_right = nominal * (1 + spread * (2 * uniform(c->world, c->robot) - 1));
  const double error_left = calibration_error * (2 * uniform(c->world, c->robot) - 1);
  const double error_right = calibration_error * (2 * uniform(c->world, c->robot) - 1);
  r->tx_clock = 3906 * uniform(c->world, c->robot); /* robots start out of step */
  uint64_t hard_seed = (uint64_t)(uniform(c->world, c->robot) * 4294967296.0);
  hard_seed = hard_seed << 32 | (uint64_t)(uniform(c->world, c->robot) * 4294967296.0);
  r->backoff_state = hard_seed ^ 0x5851f42d4c957f2dULL;
  r->last_time = c->api->time(c->world);
  /* -1: the robot's index (modulo 65536 past 65,535 robots, as a
     uint16_t takes it); else a whole number that fits a uint16_t. */
  double uid = Param(c, "kilo_uid", -1);
  if (uid != -1 && !(uid >= 0 && uid <= 65535 && uid == floor(uid))) {
    snprintf(error, error_size,
             "parameter kilo_uid is %g: a kilo_uid is a whole number 0..65535 (uint16_t), or -1 "
             "for the robot's index",
             uid);
    return -1;
  }
  if (uid == -1) uid = c->robot % 65536;

  /* The program's main(): kilo_init, callbacks, kilo_start. */
  const int hung = atomic_load(&g_main_timed_out);
  if (hung >= 0 && atomic_load(&g_hung_world) == c->world) {
    snprintf(error, error_size,
             "%s (kilobot program '%s'), robot %d: main() not called: on robot %d it did not "
             "return within %g s",
             KILOBOT_SOURCE, KILOBOT_NAME, c->robot, hung, atomic_load(&g_timeout_ms) / 1000.0);
    return -1;
  }
  const kilobot_copy_t *t = copy->table;
  Lock(copy);
  SwapIn(copy, r);
  *t->uid = (uint16_t)uid;
  const double left = lround(r->true_left + error_left),
               right = lround(r->true_right + error_right);
  *t->straight_left = *t->turn_left = (uint8_t)(left < 0 ? 0 : left > 255 ? 255 : left);
  *t->straight_right = *t->turn_right = (uint8_t)(right < 0 ? 0 : right > 255 ? 255 : right);
  t->robot->hard_state = hard_seed;
  t->robot->voltage = r->voltage;
  t->robot->temperature = r->temperature;
  Call call = {.kind = kMain, .main = t->program_main};
  const int sig = Guarded(&call);
  if (sig == 0) SwapOut(copy, r);
  Unlock(copy);
  if (sig != 0) {
    if (sig == g_watchdog_signal) {
      atomic_store(&g_hung_world, c->world);
      int none = -1;
      atomic_compare_exchange_strong(&g_main_timed_out, &none, c->robot);
    }
    Failure(c, sig, "main()", error, error_size, NULL);
    return -1;
  }
  return 0;
}

static int Step(const SwarmsimCallContext *c, void *state, char *error, size_t error_size,
                void *unused) {
  (void)unused;
  Robot *r = state;
  Copy *copy = &g_copies[r->copy];
  const kilobot_copy_t *t = copy->table;
  const SwarmsimWorldApi *api = c->api;

  const double now = api->time(c->world);
  const long long now_us = llround(now * 1e6);
  if (atomic_load_explicit(&g_timed_out_at, memory_order_relaxed) == now_us &&
      atomic_load_explicit(&g_hung_world, memory_order_relaxed) == c->world)
    return 0; /* another robot's program hung in this step: the run is ending */
  const double dt = now - r->last_time;
  r->last_time = now;
  /* The world's readings, before taking the lock. */
  int16_t ambient = -1;
  double light = 0;
  if (r->light != 0 && api->read_sensor_value(c->world, r->light, &light) == 0) {
    const double adc = floor(light * r->ambient_scale + 0.5);
    ambient = (int16_t)(adc < 0 ? 0 : adc > 1023 ? 1023 : adc);
  }
  int sent = -1;
  if (r->ir != 0 && r->tx_pending) sent = api->ir_sent(c->world, r->ir);
  SwarmsimIrMessage heard[kMaxMessages];
  int heard_count = r->ir != 0 ? api->ir_receive(c->world, r->ir, heard, kMaxMessages) : 0;
  if (heard_count < 0) r->ir = 0, heard_count = 0; /* no transceiver: no messages */
  if (heard_count > kMaxMessages) heard_count = kMaxMessages;

  Lock(copy);
  SwapIn(copy, r);
  kilobot_robot_t *rt = t->robot;
  *t->ticks = (uint32_t)floor(now * TICKS_PER_SEC + 1e-9);
  rt->ambient = ambient;
  Call call = {.kind = kVoid};
  const char *what = "";
  int sig = 0;
  /* Last step's transmission: done, or the channel was busy (back off). */
  if (r->tx_pending) {
    r->tx_pending = 0;
    if (sent == 1) {
      r->tx_clock = 0;
      what = "kilo_message_tx_success()", call.void_fn = *t->tx_success;
      sig = Guarded(&call);
    } else {
      /* 0..255 cycles, as kilolib's rand() & 0xFF */
      r->backoff_state = r->backoff_state * 6364136223846793005ULL + 1442695040888963407ULL;
      r->tx_wait = (double)(r->backoff_state >> 56);
    }
  }
  /* Messages heard, in arrival order (kilolib's receive interrupt). */
  for (int i = 0; sig == 0 && i < heard_count; ++i) {
    message_t message;
    if (heard[i].size != sizeof message) continue;
    memcpy(&message, heard[i].data, sizeof message);
    if (message.type >= SPECIAL) continue; /* the bootloader's */
    if (r->crc_check && message.crc != message_crc(&message)) continue;
    double mm = floor(heard[i].distance * 1000 + 0.5);
    mm = mm < 0 ? 0 : mm > 1023 ? 1023 : mm;
    distance_measurement_t distance = {(int16_t)mm, (int16_t)mm};
    call.kind = kRx, call.rx = *t->rx, call.message = &message, call.distance = &distance;
    what = "kilo_message_rx()";
    sig = Guarded(&call);
  }
  /* setup() once, then loop() (kilolib: after the run message). */
  if (KILOBOT_DELAY && sig == 0 && rt->started) {
    /* On the robot's own stack, resumed unless a delay() still waits. */
    if (r->coroutine == NULL && (r->coroutine = NewCoroutine(t)) == NULL) {
      Unlock(copy);
      snprintf(error, error_size, "out of memory (a program stack for delay())");
      return -1;
    }
    if (r->coroutine->wake <= now + 1e-9) {
      r->coroutine->wake = 0;
      r->set_up = 1;
      t_now = now;
      call.kind = kResume, call.coroutine = r->coroutine;
      sig = Guarded(&call);
      what = r->coroutine->in_setup ? "setup()" : "loop()";
    }
  } else {
    if (sig == 0 && rt->started && !r->set_up) {
      r->set_up = 1;
      call.kind = kVoid, call.void_fn = rt->setup, what = "setup()";
      sig = call.void_fn != NULL ? Guarded(&call) : 0;
    }
    if (sig == 0 && rt->started && rt->loop != NULL) {
      call.kind = kVoid, call.void_fn = rt->loop, what = "loop()";
      sig = Guarded(&call);
    }
  }
  /* Every kilo_tx_period cycles, a message to send. */
  uint8_t outgoing[sizeof(message_t)];
  int send = 0;
  if (sig == 0 && r->ir != 0 && r->set_up) {
    const double cycles = dt * kCyclesPerSecond;
    r->tx_clock += cycles;
    r->tx_wait = r->tx_wait > cycles ? r->tx_wait - cycles : 0;
    if (r->tx_clock > *t->tx_period && r->tx_wait <= 0) {
      call.kind = kTx, call.tx = *t->tx, what = "kilo_message_tx()";
      sig = Guarded(&call);
      if (sig == 0 && call.result != NULL) {
        memcpy(outgoing, call.result, sizeof outgoing);
        send = 1;
      }
    }
  }
  if (sig == 0) SwapOut(copy, r);
  kilobot_robot_t outputs = *rt;
  Unlock(copy);
  if (sig != 0) {
    if (sig == g_watchdog_signal) {
      atomic_store(&g_hung_world, c->world);
      atomic_store(&g_timed_out_at, now_us);
    }
    Failure(c, sig, what, error, error_size, r->coroutine);
    return -1;
  }
  if (send) {
    message_t check;
    memcpy(&check, outgoing, sizeof check);
    /* The receivers' check; with crc_check: 0 (for every robot of a model,
       as a rule) nothing is dropped and nothing said. */
    if (r->crc_check && check.crc != message_crc(&check) &&
        atomic_exchange(&g_warned_crc, 1) == 0)
      fprintf(stderr,
              "warning: %s (kilobot program '%s'), robot %d sends a message whose crc is not "
              "message_crc(&msg): receivers drop it (parameter crc_check: 0 keeps it; warned "
              "once)\n",
              KILOBOT_SOURCE, KILOBOT_NAME, c->robot);
    if (api->ir_send(c->world, c->robot, r->ir, outgoing, sizeof outgoing) == 0) r->tx_pending = 1;
  }
  ApplyOutputs(c, r, &outputs);
  return 0;
}

static void Cleanup(const SwarmsimCallContext *c, void *state, void *unused) {
  (void)c, (void)unused;
  if (state != NULL) FreeCoroutine(((Robot *)state)->coroutine);
  free(state); /* the Robot and its image */
}

__attribute__((visibility("default"))) int swarmsim_plugin_abi_version(void) {
  return SWARMSIM_PLUGIN_ABI_VERSION;
}

__attribute__((visibility("default"))) int swarmsim_plugin_register(const SwarmsimRegistrar *r) {
  if (g_copy_count == 0 && LoadCopies() != 0)
    snprintf(g_load_error, sizeof g_load_error, "out of memory");
  pthread_once(&g_signals_once, InstallHandlers);
  /* A new world: an earlier one's hang is not its own (a freed world's
     address may come back). */
  atomic_store(&g_hung_world, NULL);
  atomic_store(&g_timed_out_at, -1);
  atomic_store(&g_main_timed_out, -1);
  r->set_info(r->impl, KILOBOT_NAME, "1.0", "Kilobot program " KILOBOT_SOURCE " (swarm/kilobot)");
  return r->add_controller(r->impl, KILOBOT_NAME, "runs the Kilobot program " KILOBOT_SOURCE, Init,
                           Step, Cleanup, NULL);
}
