// A one-line progress bar on stderr for long CLI work (only drawn when stderr is a terminal,
// otherwise one line per stage so logs stay readable).
#pragma once

#include <string>

namespace inbetween::client {

class ProgressBar {
 public:
  ProgressBar();
  // fraction in [0, 1]; label says what is being done.
  void Update(const std::string& label, double fraction);
  void Finish();

 private:
  bool tty_;
  std::string last_label_;
  int last_percent_ = -1;
};

}  // namespace inbetween::client
