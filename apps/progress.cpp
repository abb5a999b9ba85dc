#include "apps/progress.h"

#include <unistd.h>

#include <cstdio>

namespace saresgs::apps {

void Progress::update(const std::string& stage, int done, int total, const std::string& detail) {
  const auto now = std::chrono::steady_clock::now();
  if (stage != stage_) {
    stage_ = stage;
    start_ = now;
    last_decile_ = -1;
  }
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? done / elapsed : 0.0;
  const double eta = (rate > 0 && total > done) ? (total - done) / rate : 0.0;
  const bool tty = ::isatty(STDERR_FILENO);
  const int decile = total > 0 ? 10 * done / total : 10;
  if (!tty && decile == last_decile_ && done != total && now - last_draw_ < kLogInterval) return;
  // A terminal is redrawn at most ~10 times a second: fast loops stay fast.
  if (tty && done != total && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  last_decile_ = decile;
  std::fprintf(stderr, "%s[%s] %d/%d  %.1f/s  ETA %.0fs%s%s%s", tty ? "\r" : "", stage.c_str(), done,
               total, rate, eta, detail.empty() ? "" : "  ", detail.c_str(), (tty && done < total) ? "   " : "\n");
  std::fflush(stderr);
}

}  // namespace saresgs::apps
