// Progress output for long CLI work on stderr: a one-line bar with percentage and ETA on a
// terminal, one line per stage otherwise, one JSON object per event with --progress json, or
// nothing with -q.
#pragma once

#include <chrono>
#include <string>

namespace inbetween::client {

enum class ProgressMode { kAuto, kJson, kQuiet };

class ProgressBar {
 public:
  explicit ProgressBar(ProgressMode mode = ProgressMode::kAuto);
  // fraction in [0, 1], or < 0 when the end is not known (comesh optimization: a bar then shows
  // the detail and the elapsed time instead of a percentage, redrawn at most 10 times a second;
  // JSON events carry fraction 0); label says what is being done (a new label starts a new
  // stage).
  void Update(const std::string& label, double fraction, const std::string& detail = "");
  void Finish();

 private:
  ProgressMode mode_;
  bool tty_;
  std::string last_label_;
  int last_percent_ = -1;
  std::string last_detail_;
  std::string pending_;  // a detail the 100 ms throttle held back (unknown-end stages)
  std::chrono::steady_clock::time_point last_draw_;
  std::chrono::steady_clock::time_point stage_start_;
};

}  // namespace inbetween::client
