// Admission control for the heavy stages (BuildMultimesh, OptimizeComesh, Inbetween): at most
// `max_running` run at once, at most `max_queued` wait for a slot, at most `max_per_owner` run or
// wait per token. Heavy handlers therefore never take more than max_running cores, and unary
// calls (which never queue here) are not starved. A full queue is RESOURCE_EXHAUSTED with a retry
// hint; a caller that goes away while queued leaves the queue.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <map>
#include <mutex>
#include <string>

#include "absl/status/statusor.h"

namespace inbetween::server {

struct HeavyJobOptions {
  int max_running = 0;    // 0 = std::thread::hardware_concurrency()
  int max_queued = -1;    // < 0 = 4 * max_running
  int max_per_owner = 0;  // 0 = max_running
};

class HeavyJobs {
 public:
  // Releases its slot on destruction.
  class Slot {
   public:
    Slot(Slot&& other) noexcept : jobs_(other.jobs_), owner_(std::move(other.owner_)) {
      other.jobs_ = nullptr;
    }
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;
    Slot& operator=(Slot&&) = delete;
    ~Slot();

   private:
    friend class HeavyJobs;
    Slot(HeavyJobs* jobs, std::string owner) : jobs_(jobs), owner_(std::move(owner)) {}
    HeavyJobs* jobs_;
    std::string owner_;
  };

  explicit HeavyJobs(HeavyJobOptions options);

  // Waits for a slot. RESOURCE_EXHAUSTED (naming the limit, with a retry hint) when the queue or
  // the owner's share is full; `stopped` is polled while waiting and, once true, the wait ends
  // with CANCELLED.
  absl::StatusOr<Slot> Acquire(const std::string& owner, const std::function<bool()>& stopped);

  int running() const;
  int queued() const;
  int max_running() const { return max_running_; }
  int max_queued() const { return max_queued_; }
  int max_per_owner() const { return max_per_owner_; }

 private:
  void Release(const std::string& owner);

  int max_running_;
  int max_queued_;
  int max_per_owner_;
  mutable std::mutex mutex_;
  std::condition_variable slot_freed_;
  int running_ = 0;
  int queued_ = 0;
  std::map<std::string, int> per_owner_;  // running + queued
};

// Seconds a client should wait before retrying a RESOURCE_EXHAUSTED heavy call.
inline constexpr int kBusyRetryAfterSeconds = 2;

}  // namespace inbetween::server
