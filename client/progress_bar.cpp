// Terminal / JSON progress output (see progress_bar.h).
#include "client/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "nlohmann/json.hpp"

namespace inbetween::client {

ProgressBar::ProgressBar(ProgressMode mode) : mode_(mode), tty_(isatty(STDERR_FILENO) == 1) {}

void ProgressBar::Update(const std::string& label, double fraction, const std::string& detail) {
  if (mode_ == ProgressMode::kQuiet) return;
  const bool unknown = !(fraction >= 0.0);
  fraction = unknown ? 0.0 : std::clamp(fraction, 0.0, 1.0);
  const int percent = static_cast<int>(fraction * 100.0 + 0.5);
  const auto now = std::chrono::steady_clock::now();
  if (label != last_label_) {
    if (tty_ && !last_label_.empty() && mode_ == ProgressMode::kAuto) std::fprintf(stderr, "\n");
    stage_start_ = now;
  } else if (unknown) {
    // A new detail (JSON), or a redraw of the bar's detail at most every 100 ms.
    if (detail == last_detail_) return;
    if (mode_ == ProgressMode::kAuto &&
        (!tty_ || now - last_draw_ < std::chrono::milliseconds(100))) {
      pending_ = detail;  // drawn by the next redraw, or by Finish
      return;
    }
  } else if (percent == last_percent_) {
    return;
  }
  last_detail_ = detail;
  last_draw_ = now;
  pending_.clear();
  const double elapsed = std::chrono::duration<double>(now - stage_start_).count();
  if (mode_ == ProgressMode::kJson) {
    nlohmann::json event = {{"stage", label}, {"fraction", fraction}, {"elapsed_s", elapsed}};
    if (!detail.empty()) event["detail"] = detail;
    std::fprintf(stderr, "%s\n", event.dump().c_str());
  } else if (!tty_) {
    // Logs: one line when a stage starts and one when it completes.
    if (unknown) {
      if (label != last_label_) std::fprintf(stderr, "%s\n", label.c_str());
    } else if (label != last_label_ || (percent == 100 && last_percent_ != 100)) {
      std::fprintf(stderr, "%s %d%%\n", label.c_str(), percent);
    }
  } else if (unknown) {
    std::fprintf(stderr, "\r%-16.16s %6.1fs  %-56.56s", label.c_str(), elapsed, detail.c_str());
    std::fflush(stderr);
  } else {
    constexpr int kWidth = 30;
    const int filled = percent * kWidth / 100;
    char eta[32] = "";
    if (fraction > 0.02 && fraction < 1.0) {
      std::snprintf(eta, sizeof(eta), " ETA %.1fs", elapsed * (1.0 - fraction) / fraction);
    }
    std::fprintf(stderr, "\r%-16.16s [%.*s%*s] %3d%%%-14s", label.c_str(), filled,
                 "##############################", kWidth - filled, "", percent, eta);
    std::fflush(stderr);
  }
  last_label_ = label;
  last_percent_ = percent;
}

void ProgressBar::Finish() {
  // The last detail of a stage whose end was not known, if the throttle held it back.
  if (mode_ == ProgressMode::kAuto && tty_ && !pending_.empty()) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - stage_start_).count();
    std::fprintf(stderr, "\r%-16.16s %6.1fs  %-56.56s", last_label_.c_str(), elapsed,
                 pending_.c_str());
  }
  pending_.clear();
  if (mode_ == ProgressMode::kAuto && tty_ && !last_label_.empty()) std::fprintf(stderr, "\n");
  last_label_.clear();
  last_percent_ = -1;
  last_detail_.clear();
}

}  // namespace inbetween::client
