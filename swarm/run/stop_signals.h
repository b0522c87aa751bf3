// SIGINT, SIGTERM and SIGHUP as requests to stop at the next good point (a
// run's step boundary, a sweep's next run): while a StopSignals lives, the
// first such signal is only noted (StopSignals::Received()), and so are
// repeats within kGraceMs of it (Ctrl-C pressed twice: the outputs are
// being written); a signal after that acts as usual, so a stuck program can
// still be ended. Without SA_RESTART, a signal also ends a blocking wait
// (the sweep's for its runs). A SIGHUP ignored when the StopSignals is made
// (nohup) stays ignored.
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
  // ms after the first signal during which another is the same request.
  static constexpr long kGraceMs = 3000;
  // Another grace period (tests: 0, the second signal acts at once).
  static void SetGraceMs(long ms);

 private:
  static constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};
  std::array<struct sigaction, 3> saved_{};
};

}  // namespace swarmsim
