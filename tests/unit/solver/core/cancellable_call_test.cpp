// RunCancellable: runs inline without a token, on a helper with one, returns false on a cancel
// while the work is still running (the helper finishes it on its own), rethrows the work's
// exception, and does not start work for a token already set.
#include "solver/core/cancellable_call.h"

#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <memory>
#include <stdexcept>
#include <thread>

namespace inbetween::solver {
namespace {

TEST(CancellableCallTest, WithoutATokenRunsOnTheCallingThread) {
  std::thread::id ran_on;
  EXPECT_TRUE(RunCancellable([&] { ran_on = std::this_thread::get_id(); }, nullptr));
  EXPECT_EQ(ran_on, std::this_thread::get_id());
}

TEST(CancellableCallTest, WithAnUnsetTokenRunsOnAHelperAndItsEffectsAreVisible) {
  CancelToken token;
  auto result = std::make_shared<int>(0);
  std::thread::id ran_on = std::this_thread::get_id();
  EXPECT_TRUE(RunCancellable(
      [result, &ran_on] {
        *result = 42;
        ran_on = std::this_thread::get_id();
      },
      &token));
  EXPECT_EQ(*result, 42);
  EXPECT_NE(ran_on, std::this_thread::get_id());
}

// The work blocks until the test lets it go, which happens only after RunCancellable returned:
// a RunCancellable that waited for the work would never return (the test would time out).
TEST(CancellableCallTest, CancelReturnsWhileTheWorkIsStillRunningAndTheHelperFinishesIt) {
  CancelToken token;
  auto release = std::make_shared<std::promise<void>>();
  auto finished = std::make_shared<std::promise<void>>();
  std::shared_future<void> released = release->get_future().share();
  std::future<void> done = finished->get_future();
  auto started = std::make_shared<std::atomic<bool>>(false);
  std::thread canceller([&] {
    while (!started->load()) std::this_thread::yield();
    token.Cancel();
  });
  const bool completed = RunCancellable(
      [released, finished, started] {
        started->store(true);
        released.wait();
        finished->set_value();
      },
      &token);
  canceller.join();
  EXPECT_FALSE(completed);
  EXPECT_EQ(done.wait_for(std::chrono::seconds(0)), std::future_status::timeout);
  release->set_value();
  done.wait();  // the detached helper ran the work to its end
}

TEST(CancellableCallTest, AnExceptionOfTheWorkIsRethrown) {
  CancelToken token;
  EXPECT_THROW(RunCancellable([] { throw std::runtime_error("analysis failed"); }, &token),
               std::runtime_error);
}

TEST(CancellableCallTest, ATokenAlreadySetStartsNothing) {
  CancelToken token;
  token.Cancel();
  bool ran = false;
  EXPECT_FALSE(RunCancellable([&] { ran = true; }, &token));
  EXPECT_FALSE(ran);
}

}  // namespace
}  // namespace inbetween::solver
