#include "swarm/run/stop_signals.h"

#include <pthread.h>
#include <time.h>

namespace swarmsim {
namespace {

volatile std::sig_atomic_t g_stop_signal = 0;
// When the first was noted (CLOCK_MONOTONIC, whole ms): written by the
// handler only, before g_stop_signal.
volatile std::sig_atomic_t g_first_ms = 0;
int g_depth = 0;  // StopSignals alive (the program's thread only)
volatile std::sig_atomic_t g_grace_ms = StopSignals::kGraceMs;

long NowMs() {  // async-signal-safe (clock_gettime)
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<long>(now.tv_sec % 1000000) * 1000 + now.tv_nsec / 1000000;
}

extern "C" void OnStopSignal(int sig) {
  if (g_stop_signal == 0) {
    g_first_ms = static_cast<std::sig_atomic_t>(NowMs());
    g_stop_signal = sig;
    return;
  }
  // A repeat within the grace period (Ctrl-C pressed twice) is the same
  // request: the run is writing its outputs. Later, the program has not
  // stopped as asked: the signal acts as it would (its default: the end).
  const long since = NowMs() - g_first_ms;
  if (since >= 0 && since < g_grace_ms) return;
  signal(sig, SIG_DFL);
  raise(sig);  // blocked while this handler runs: delivered as it returns
}

}  // namespace

StopSignals::StopSignals() {
  // A nested one (the run's, inside the program's for the load) keeps a
  // signal the outer one noted.
  if (g_depth++ == 0) g_stop_signal = 0;
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  action.sa_flags = 0;
  sigemptyset(&action.sa_mask);
  for (const int sig : kSignals) sigaddset(&action.sa_mask, sig);  // one handler at a time
  for (size_t i = 0; i < kSignals.size(); ++i) {
    sigaction(kSignals[i], nullptr, &saved_[i]);
    // nohup: a hang-up the program was started to ignore stays ignored (the
    // handler replaced it, and closing the terminal stopped a nohup'd run).
    if (kSignals[i] == SIGHUP && saved_[i].sa_handler == SIG_IGN) continue;
    sigaction(kSignals[i], &action, nullptr);
  }
  // A program started with them blocked (a batch system's wrapper) would
  // never see them; a signal already pending arrives now, and is noted.
  sigset_t mask;
  sigemptyset(&mask);
  for (const int sig : kSignals) sigaddset(&mask, sig);
  pthread_sigmask(SIG_UNBLOCK, &mask, nullptr);
}

StopSignals::~StopSignals() {
  --g_depth;
  for (size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &saved_[i], nullptr);
}

int StopSignals::Received() { return g_stop_signal; }

void StopSignals::SetGraceMs(long ms) { g_grace_ms = static_cast<std::sig_atomic_t>(ms); }

}  // namespace swarmsim
