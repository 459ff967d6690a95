// Cooperative cancellation and progress reporting for long solver stages.
#pragma once

#include <atomic>
#include <functional>
#include <string>

namespace inbetween::solver {

// Set by the caller (e.g. when a gRPC client goes away); polled by solver loops, which then
// return absl::CancelledError promptly.
class CancelToken {
 public:
  void Cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool IsCancelled() const { return cancelled_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> cancelled_{false};
};

// True when `token` is given and set: the poll every cancellable loop makes (a null token means
// "not cancellable").
inline bool Cancelled(const CancelToken* token) {
  return token != nullptr && token->IsCancelled();
}

// Progress callback: stage name, fraction done in [0, 1], short human-readable detail.
using ProgressFn = std::function<void(const std::string& stage, double fraction,
                                      const std::string& detail)>;

}  // namespace inbetween::solver
