// A cancellable wait for work that cannot poll a token itself: one long library call (CHOLMOD's
// symbolic analysis, AMD) whose only way to stop early would be to stop its thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>

#include "solver/core/cancel.h"

namespace inbetween::solver {

// Runs `work` on a helper thread while the calling thread waits, polling `cancel` every `poll`.
// Returns true once `work` has finished (its effects are then visible to the caller, and an
// exception it threw is rethrown here). Returns false as soon as the token is seen set: the
// helper is detached and runs `work` to its end on its own, after the caller has moved on, so
// `work` must own (by value or shared_ptr) everything it touches and write nothing the caller
// reads. Without a token, `work` runs on the calling thread.
inline bool RunCancellable(std::function<void()> work, const CancelToken* cancel,
                           std::chrono::microseconds poll = std::chrono::milliseconds(2)) {
  if (cancel == nullptr) {
    work();
    return true;
  }
  if (cancel->IsCancelled()) return false;
  struct State {
    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    std::exception_ptr error;
  };
  auto state = std::make_shared<State>();
  std::thread helper([state, work = std::move(work)] {
    std::exception_ptr error;
    try {
      work();
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard lock(state->mutex);
    state->done = true;
    state->error = error;
    state->finished.notify_all();
  });
  std::unique_lock lock(state->mutex);
  while (!state->finished.wait_for(lock, poll, [&] { return state->done; })) {
    if (cancel->IsCancelled()) {
      lock.unlock();
      helper.detach();
      return false;
    }
  }
  lock.unlock();
  helper.join();
  if (state->error) std::rethrow_exception(state->error);
  return true;
}

}  // namespace inbetween::solver
