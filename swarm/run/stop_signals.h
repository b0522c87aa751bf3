// SIGINT, SIGTERM and SIGHUP as requests to stop at the next good point (a
// run's step boundary, a sweep's next run): while a StopSignals lives, the
// first such signal is only noted (StopSignals::Received()); a second acts as
// usual (SA_RESETHAND), so a stuck program can still be killed. Without
// SA_RESTART, a signal also ends a blocking wait (the sweep's for its runs).
#pragma once

#include <array>
#include <csignal>

namespace swarmsim {

class StopSignals {
 public:
  StopSignals();   // clears a signal noted earlier, unless another StopSignals lives
  ~StopSignals();  // restores the previous handlers
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // The signal received, or 0. Safe from any thread.
  static int Received();

 private:
  static constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};
  std::array<struct sigaction, 3> saved_{};
};

}  // namespace swarmsim
