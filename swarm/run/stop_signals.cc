#include "swarm/run/stop_signals.h"

#include <pthread.h>

namespace swarmsim {
namespace {

volatile std::sig_atomic_t g_stop_signal = 0;
int g_depth = 0;  // StopSignals alive (the program's thread only)
extern "C" void OnStopSignal(int sig) { g_stop_signal = sig; }

}  // namespace

StopSignals::StopSignals() {
  // A nested one (the run's, inside the program's for the load) keeps a
  // signal the outer one noted.
  if (g_depth++ == 0) g_stop_signal = 0;
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  action.sa_flags = SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  for (size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &action, &saved_[i]);
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

}  // namespace swarmsim
