// CancelWatcher: poll IsCancelled() until stopped; the solver sees the token within a period.
#include "server/cancel_watcher.h"

namespace inbetween::server {

CancelWatcher::CancelWatcher(grpc::ServerContext* context, solver::CancelToken* token,
                             std::chrono::milliseconds period)
    : thread_([this, context, token, period](std::stop_token stop) {
        std::unique_lock lock(mutex_);
        while (!stop.stop_requested()) {
          if (context->IsCancelled()) {
            token->Cancel();
            return;
          }
          wake_.wait_for(lock, stop, period, [] { return false; });
        }
      }) {}

CancelWatcher::~CancelWatcher() {
  thread_.request_stop();  // wakes the condition variable wait through the stop token
  thread_.join();
}

}  // namespace inbetween::server
