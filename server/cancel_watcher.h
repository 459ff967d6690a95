// Bridges gRPC cancellation to the solver: while alive, a small thread polls the call's
// ServerContext and trips the CancelToken when the client goes away, the deadline passes or the
// server shuts down past its grace period.
#pragma once

#include <grpcpp/server_context.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "solver/core/cancel.h"

namespace inbetween::server {

class CancelWatcher {
 public:
  CancelWatcher(grpc::ServerContext* context, solver::CancelToken* token,
                std::chrono::milliseconds period = std::chrono::milliseconds(20));
  ~CancelWatcher();  // stops polling (does not cancel)
  CancelWatcher(const CancelWatcher&) = delete;
  CancelWatcher& operator=(const CancelWatcher&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::jthread thread_;
};

}  // namespace inbetween::server
