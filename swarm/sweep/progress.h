// Progress of a sweep: a bar with runs done/failed/left and an ETA on a
// terminal; plain lines (every 5% and every failure) otherwise.
#pragma once

#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <string>

namespace swarmsim {

class SweepProgress {
 public:
  // `total` runs in the sweep, `already` of them finished before this
  // session, `already_failed` of those failed.
  SweepProgress(std::ostream& os, int64_t total, int64_t already, int64_t already_failed, bool tty,
                bool enabled);
  // One run ended (ok or failed, with the failure's message).
  void RunEnded(int64_t id, bool ok, const std::string& error, int running);
  void Finish();
  int64_t done() const { return done_; }
  int64_t failed() const { return failed_; }

 private:
  void Draw(int running, bool force);

  std::ostream& os_;
  int64_t total_, already_, already_failed_;
  int64_t done_ = 0, failed_ = 0;  // this session, failed included in done
  bool tty_, enabled_;
  std::chrono::steady_clock::time_point start_, last_draw_{};
  int last_step_ = -1;  // 5% steps printed (plain mode)
};

}  // namespace swarmsim
