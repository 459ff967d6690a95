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
  // fraction in [0, 1]; label says what is being done (a new label starts a new stage).
  void Update(const std::string& label, double fraction, const std::string& detail = "");
  void Finish();

 private:
  ProgressMode mode_;
  bool tty_;
  std::string last_label_;
  int last_percent_ = -1;
  std::chrono::steady_clock::time_point stage_start_;
};

}  // namespace inbetween::client
