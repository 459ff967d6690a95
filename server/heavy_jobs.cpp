// HeavyJobs: a counting semaphore with a bounded FIFO-ish wait (condition variable) and per-owner
// counts.
#include "server/heavy_jobs.h"

#include <algorithm>
#include <chrono>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/core/error_reason.h"

namespace inbetween::server {

HeavyJobs::Slot::~Slot() {
  if (jobs_ != nullptr) jobs_->Release(owner_);
}

HeavyJobs::HeavyJobs(HeavyJobOptions options) {
  max_running_ = options.max_running > 0
                     ? options.max_running
                     : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  max_queued_ = options.max_queued >= 0 ? options.max_queued : 4 * max_running_;
  max_per_owner_ = options.max_per_owner > 0 ? options.max_per_owner : max_running_;
}

absl::StatusOr<HeavyJobs::Slot> HeavyJobs::Acquire(const std::string& owner,
                                                   const std::function<bool()>& stopped) {
  std::unique_lock lock(mutex_);
  int& mine = per_owner_[owner];
  if (mine >= max_per_owner_) {
    if (mine == 0) per_owner_.erase(owner);
    return solver::WithRetryAfter(
        solver::WithReason(
            absl::ResourceExhaustedError(absl::StrCat(
                "this token already has ", max_per_owner_,
                " heavy jobs (build, optimize, inbetween) running or queued, the limit "
                "(--max-heavy-jobs-per-token); retry after ",
                kBusyRetryAfterSeconds, " s or when one finishes")),
            solver::kReasonHeavyJobsPerToken),
        kBusyRetryAfterSeconds * 1000);
  }
  if (running_ >= max_running_) {
    if (queued_ >= max_queued_) {
      if (mine == 0) per_owner_.erase(owner);
      return solver::WithRetryAfter(
          solver::WithReason(
              absl::ResourceExhaustedError(absl::StrCat(
                  "server busy: ", running_, " heavy jobs running and ", queued_,
                  " queued, the limits (--max-heavy-jobs, --heavy-queue); retry after ",
                  kBusyRetryAfterSeconds, " s")),
              solver::kReasonServerBusy),
          kBusyRetryAfterSeconds * 1000);
    }
    ++queued_;
    ++mine;
    while (running_ >= max_running_) {
      slot_freed_.wait_for(lock, std::chrono::milliseconds(20));
      if (stopped && stopped()) {
        --queued_;
        if (--per_owner_[owner] == 0) per_owner_.erase(owner);
        return absl::CancelledError("the call stopped while waiting for a heavy-job slot");
      }
    }
    --queued_;
  } else {
    ++mine;
  }
  ++running_;
  return Slot(this, owner);
}

void HeavyJobs::Release(const std::string& owner) {
  {
    std::lock_guard lock(mutex_);
    --running_;
    auto it = per_owner_.find(owner);
    if (it != per_owner_.end() && --it->second <= 0) per_owner_.erase(it);
  }
  slot_freed_.notify_one();
}

int HeavyJobs::running() const {
  std::lock_guard lock(mutex_);
  return running_;
}

int HeavyJobs::queued() const {
  std::lock_guard lock(mutex_);
  return queued_;
}

}  // namespace inbetween::server
