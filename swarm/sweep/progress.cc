#include "swarm/sweep/progress.h"

#include <iomanip>
#include <ostream>
#include <sstream>

namespace swarmsim {
namespace {

std::string Duration(double s) {
  std::ostringstream o;
  const int64_t t = static_cast<int64_t>(s + 0.5);
  if (t >= 3600)
    o << t / 3600 << "h" << std::setw(2) << std::setfill('0') << (t % 3600) / 60 << "m";
  else if (t >= 60)
    o << t / 60 << "m" << std::setw(2) << std::setfill('0') << t % 60 << "s";
  else
    o << t << "s";
  return o.str();
}

}  // namespace

SweepProgress::SweepProgress(std::ostream& os, int64_t total, int64_t already,
                             int64_t already_failed, bool tty, bool enabled)
    : os_(os),
      total_(total),
      already_(already),
      already_failed_(already_failed),
      tty_(tty),
      enabled_(enabled),
      start_(std::chrono::steady_clock::now()) {}

void SweepProgress::RunEnded(int64_t id, bool ok, const std::string& error, int running) {
  ++done_;
  if (!ok) {
    ++failed_;
    if (enabled_) {
      if (tty_) os_ << "\r\033[K";
      os_ << "run " << id << " failed: " << error << "\n";
    }
  }
  Draw(running, !ok);
}

void SweepProgress::Draw(int running, bool force) {
  if (!enabled_ || total_ <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  const int64_t finished = already_ + done_;
  const int64_t left = total_ - finished;
  const int step = static_cast<int>(20 * finished / total_);
  if (tty_) {
    if (!force && left > 0 && now - last_draw_ < std::chrono::milliseconds(100)) return;
  } else if (step == last_step_ && !force && left > 0) {
    return;
  }
  last_draw_ = now;
  last_step_ = step;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double frac = static_cast<double>(finished) / static_cast<double>(total_);
  std::ostringstream line;
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(frac * kWidth);
    line << "\r\033[K[" << std::string(filled, '#') << std::string(kWidth - filled, ' ') << "] ";
  }
  line << finished << "/" << total_ << " runs  " << already_failed_ + failed_ << " failed  " << left
       << " left  " << running << " running  elapsed " << Duration(elapsed);
  if (done_ > 0 && left > 0)
    line << "  ETA " << Duration(elapsed / static_cast<double>(done_) * static_cast<double>(left));
  os_ << line.str() << (tty_ ? "" : "\n") << std::flush;
}

void SweepProgress::Finish() {
  if (last_step_ != 20 || done_ == 0) Draw(0, true);  // unless the final state is shown
  if (enabled_ && tty_) os_ << "\n" << std::flush;
}

}  // namespace swarmsim
