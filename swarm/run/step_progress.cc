#include "swarm/run/step_progress.h"

#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <utility>

namespace swarmsim {

std::string RealTimeFactorText(double factor) {
  std::ostringstream s;
  s << std::fixed;
  if (!(factor > 0) || factor >= 0.995 || !std::isfinite(factor)) {
    s << std::setprecision(1) << factor;
  } else {
    // Two significant digits: 0.68, 0.068, 0.0068.
    const int digits = 1 - static_cast<int>(std::floor(std::log10(factor)));
    s << std::setprecision(digits < 2 ? 2 : digits) << factor;
  }
  return s.str();
}

StepProgress::StepProgress(std::ostream& os, int64_t total, bool enabled, bool tty,
                           std::function<std::string()> note)
    : os_(os), total_(total), enabled_(enabled), tty_(tty), note_(std::move(note)) {}

void StepProgress::Begin(double sim_time, double wall) {
  begin_sim_ = sim_time;
  begin_wall_ = wall;
}

void StepProgress::Update(int64_t done, double sim_time, double wall) {
  if (!enabled_ || total_ <= 0) return;
  const int decile = static_cast<int>(10 * done / total_);
  if (tty_) {
    if (done != total_ && last_wall_ >= 0 && wall - last_wall_ < 0.1) return;
  } else if (decile == last_decile_) {
    return;
  }
  last_wall_ = wall;
  last_decile_ = decile;
  const double elapsed = wall - begin_wall_;
  const double frac = static_cast<double>(done) / static_cast<double>(total_);
  const double eta = done > 0 ? elapsed * (1 - frac) / frac : 0;
  const double factor = elapsed > 0 ? (sim_time - begin_sim_) / elapsed : 0;
  std::ostringstream line;
  line << std::fixed << std::setprecision(1);
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(frac * kWidth);
    line << "\r[" << std::string(filled, '#') << std::string(kWidth - filled, ' ') << "] ";
  }
  line << std::setw(3) << static_cast<int>(100 * frac) << "%  step " << done << "/" << total_
       << "  sim " << sim_time << " s  " << RealTimeFactorText(factor) << "x real time"
       << "  ETA " << eta << " s";
  if (note_)
    if (const std::string note = note_(); !note.empty()) line << "  " << note;
  if (tty_) line << "\x1b[K";  // the rest of a longer line before
  os_ << line.str() << (tty_ ? "" : "\n") << std::flush;
}

void StepProgress::Finish() {
  if (enabled_ && tty_) os_ << "\n" << std::flush;
}

}  // namespace swarmsim
