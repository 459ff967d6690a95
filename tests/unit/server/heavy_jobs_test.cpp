// HeavyJobs: slots, the queue bound, the per-owner share, leaving the queue when stopped.
#include "server/heavy_jobs.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <optional>
#include <thread>

namespace inbetween::server {
namespace {

using ::testing::HasSubstr;

TEST(HeavyJobsTest, FullQueueIsResourceExhaustedWithTheFlag) {
  HeavyJobs jobs({.max_running = 1, .max_queued = 0, .max_per_owner = 5});
  auto first = jobs.Acquire("a", nullptr);
  ASSERT_TRUE(first.ok());
  EXPECT_EQ(jobs.running(), 1);
  auto second = jobs.Acquire("b", nullptr);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(second.status().message(), HasSubstr("--max-heavy-jobs"));
  EXPECT_THAT(second.status().message(), HasSubstr("retry after"));
}

TEST(HeavyJobsTest, PerOwnerShare) {
  HeavyJobs jobs({.max_running = 4, .max_queued = 4, .max_per_owner = 1});
  auto a = jobs.Acquire("a", nullptr);
  ASSERT_TRUE(a.ok());
  auto again = jobs.Acquire("a", nullptr);
  EXPECT_EQ(again.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(again.status().message(), HasSubstr("--max-heavy-jobs-per-token"));
  EXPECT_TRUE(jobs.Acquire("b", nullptr).ok());
}

TEST(HeavyJobsTest, QueuedCallGetsTheFreedSlotOrLeavesWhenStopped) {
  HeavyJobs jobs({.max_running = 1, .max_queued = 2, .max_per_owner = 3});
  std::optional<HeavyJobs::Slot> held;
  held.emplace(*jobs.Acquire("a", nullptr));
  std::atomic<bool> got{false};
  std::thread waiter([&] {
    auto slot = jobs.Acquire("b", nullptr);
    got = slot.ok();
  });
  while (jobs.queued() == 0) std::this_thread::yield();
  held.reset();
  waiter.join();
  EXPECT_TRUE(got);
  EXPECT_EQ(jobs.running(), 0);

  held.emplace(*jobs.Acquire("a", nullptr));
  std::atomic<bool> stop{false};
  absl::Status status;
  std::thread stopped([&] { status = jobs.Acquire("c", [&] { return stop.load(); }).status(); });
  while (jobs.queued() == 0) std::this_thread::yield();
  stop = true;
  stopped.join();
  EXPECT_EQ(status.code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(jobs.queued(), 0);
}

}  // namespace
}  // namespace inbetween::server
