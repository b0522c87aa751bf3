// The progress of a run's steps (swarmsim run, not --quiet): a bar on a
// terminal redrawn at most every 0.1 s, a plain line every 10% otherwise.
// Its real-time factor and ETA are of the steps alone, counted from the end
// of the world's start (a million robots start in 10-30 s: counted in, the
// first line's ETA was 4x the run's rest), and of this run's simulated time
// (a run resumed with --load-state at 12 s does not count those 12 s).
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>

namespace swarmsim {

// A real-time factor as printed: one decimal from 1x up, else two
// significant digits ("0.068", not "0.0": a million robots' 0.068x).
std::string RealTimeFactorText(double factor);

class StepProgress {
 public:
  // `total` steps; nothing printed unless `enabled`; `note()`, if set, is
  // appended to each line (a sweep run's "run 3 of 20").
  StepProgress(std::ostream& os, int64_t total, bool enabled, bool tty,
               std::function<std::string()> note);

  // The steps begin: `sim_time` is the world's time now, and `wall` the
  // seconds on the caller's clock.
  void Begin(double sim_time, double wall);
  // `done` of the total steps are done at `sim_time`, `wall` seconds.
  void Update(int64_t done, double sim_time, double wall);
  // Ends the terminal's bar with a line break.
  void Finish();

 private:
  std::ostream& os_;
  int64_t total_;
  bool enabled_;
  bool tty_;
  std::function<std::string()> note_;
  double begin_sim_ = 0, begin_wall_ = 0;
  double last_wall_ = -1;  // of the last line drawn (-1: none yet)
  int last_decile_ = -1;
};

}  // namespace swarmsim
