// Terminal progress bar (see progress_bar.h).
#include "client/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace inbetween::client {

ProgressBar::ProgressBar() : tty_(isatty(STDERR_FILENO) == 1) {}

void ProgressBar::Update(const std::string& label, double fraction) {
  const int percent = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0 + 0.5);
  if (label == last_label_ && percent == last_percent_) return;
  if (!tty_) {
    // Logs: one line when a stage starts and one when it completes.
    if (label != last_label_ || (percent == 100 && last_percent_ != 100)) {
      std::fprintf(stderr, "%s %d%%\n", label.c_str(), percent);
    }
  } else {
    constexpr int kWidth = 30;
    const int filled = percent * kWidth / 100;
    std::fprintf(stderr, "\r%-24.24s [%.*s%*s] %3d%%", label.c_str(), filled,
                 "##############################", kWidth - filled, "", percent);
    std::fflush(stderr);
  }
  last_label_ = label;
  last_percent_ = percent;
}

void ProgressBar::Finish() {
  if (tty_ && !last_label_.empty()) std::fprintf(stderr, "\n");
  last_label_.clear();
  last_percent_ = -1;
}

}  // namespace inbetween::client
