#include "apps/progress.h"

#include <unistd.h>

#include <cstdio>

namespace saresgs::apps {

void Progress::update(const std::string& stage, int done, int total, const std::string& detail,
                      const std::string& phase) {
  const auto now = std::chrono::steady_clock::now();
  if (stage != stage_) {
    stage_ = stage;
    start_ = now;
    last_decile_ = -1;
    last_done_ = -1;
  }
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? done / elapsed : 0.0;
  const double eta = (rate > 0 && total > done) ? (total - done) / rate : 0.0;
  const bool tty = ::isatty(STDERR_FILENO);
  const int decile = total > 0 ? 10 * done / total : 10;
  const bool reached_total = done == total && last_done_ != total;
  last_done_ = done;
  if (!tty && phase == last_phase_ && decile == last_decile_ && !reached_total && now - last_draw_ < kLogInterval)
    return;
  // A terminal is redrawn at most ~10 times a second: fast loops stay fast.
  if (tty && !reached_total && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  last_decile_ = decile;
  last_phase_ = phase;
  std::fprintf(stderr, "%s[%s] %d/%d  %.1f/s  ETA %.0fs%s%s%s", tty ? "\r" : "", stage.c_str(), done, total, rate, eta,
               detail.empty() ? "" : "  ", detail.c_str(), (tty && !reached_total) ? "   " : "\n");
  std::fflush(stderr);
}

}  // namespace saresgs::apps
