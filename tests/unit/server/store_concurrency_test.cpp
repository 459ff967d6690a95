// The server's shared state under concurrent use, without gRPC: the session stores (memory and
// directory), the heavy-job pool and the metrics registry, each hammered from several threads
// with invariants checked at the end (no lost update, limits never exceeded, every observation
// counted). These are the parts the RPC handlers share across calls; `scripts/sanitize
// tsan-server` runs this file under ThreadSanitizer, which can check them because none of their
// synchronisation goes through gRPC's or Abseil's uninstrumented locks (docs/hardening.md).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "server/dir_session_store.h"
#include "server/heavy_jobs.h"
#include "server/metrics.h"
#include "server/session_store.h"
#include "tests/unit/server/store_writers.h"

namespace inbetween::server {
namespace {

namespace fs = std::filesystem;
using testing::IncrementLoop;

constexpr int kWriters = 4;
constexpr int kIncrementsPerWriter = 150;

SessionState NewState(const std::string& owner, const std::string& name) {
  SessionState state;
  state.owner = owner;
  state.session.set_display_name(name);
  return state;
}

// Writers race on one session while other threads list, count, read, and create and delete
// sessions of their own (and, for stores with a cache, evict idle sessions so that reads reload
// from disk in the middle of the writes).
void HammerStore(SessionStore& store) {
  absl::StatusOr<SessionState> shared = store.Create(NewState("alice", "0"));
  ASSERT_TRUE(shared.ok()) << shared.status();
  const std::string id = shared->session.id();
  std::atomic<bool> done{false};
  std::atomic<int> aborted{0};
  std::vector<std::thread> threads;
  for (int w = 0; w < kWriters; ++w) {
    threads.emplace_back([&] { aborted += IncrementLoop(store, id, kIncrementsPerWriter); });
  }
  // Creates and deletes sessions of another owner while listing alice's.
  threads.emplace_back([&] {
    int n = 0;
    while (!done.load()) {
      absl::StatusOr<SessionState> s = store.Create(NewState("bob", "b" + std::to_string(n++)));
      ASSERT_TRUE(s.ok()) << s.status();
      ASSERT_TRUE(store.Delete(s->session.id(), 0).ok());
    }
  });
  threads.emplace_back([&] {
    while (!done.load()) {
      absl::StatusOr<SessionPage> page = store.List(10, "", "alice");
      ASSERT_TRUE(page.ok()) << page.status();
      ASSERT_EQ(page->sessions.size(), 1u);
      EXPECT_EQ(page->sessions[0].session.id(), id);
      EXPECT_EQ(store.CountOwned("alice"), 1u);
      EXPECT_LE(store.Count(), 2u);
      absl::StatusOr<SessionState> s = store.GetLatest(id);
      ASSERT_TRUE(s.ok()) << s.status();
      // Every stored version carries the counter of its own write: version = 1 + counter.
      EXPECT_EQ(s->session.version(), 1u + std::stoul(s->session.display_name()));
    }
  });
  threads.emplace_back([&] {
    while (!done.load()) {
      store.EvictIdle(std::chrono::steady_clock::now());
      std::this_thread::yield();
    }
  });
  for (int w = 0; w < kWriters; ++w) threads[w].join();
  done = true;
  for (size_t t = kWriters; t < threads.size(); ++t) threads[t].join();

  absl::StatusOr<SessionState> final_state = store.Get(id);
  ASSERT_TRUE(final_state.ok()) << final_state.status();
  EXPECT_EQ(final_state->session.display_name(), std::to_string(kWriters * kIncrementsPerWriter));
  EXPECT_EQ(final_state->session.version(), 1u + kWriters * kIncrementsPerWriter);
  EXPECT_EQ(store.Count(), 1u);
  // Not asserted (scheduling decides), but printed: how contended the run was.
  std::printf("%d ABORTED answers for %d writes\n", aborted.load(),
              kWriters * kIncrementsPerWriter);
}

TEST(StoreConcurrencyTest, MemoryStoreLosesNoUpdateUnderConcurrentWriters) {
  MemorySessionStore store;
  HammerStore(store);
}

TEST(StoreConcurrencyTest, DirStoreLosesNoUpdateWhileEvictingAndReloading) {
  const fs::path root =
      fs::temp_directory_path() / ("store_concurrency_" + std::to_string(getpid()));
  fs::remove_all(root);
  {
    DirStoreOptions options;
    options.max_cached = 1;  // every other session pushes the shared one out of memory
    absl::StatusOr<std::unique_ptr<DirSessionStore>> store =
        DirSessionStore::Open(root.string(), options);
    ASSERT_TRUE(store.ok()) << store.status();
    HammerStore(**store);
  }
  // What the writers left on disk is what a restarted server sees.
  {
    absl::StatusOr<std::unique_ptr<DirSessionStore>> reopened =
        DirSessionStore::Open(root.string());
    ASSERT_TRUE(reopened.ok()) << reopened.status();
    absl::StatusOr<SessionPage> page = (*reopened)->List(10, "", "alice");
    ASSERT_TRUE(page.ok()) << page.status();
    ASSERT_EQ(page->sessions.size(), 1u);
    absl::StatusOr<SessionState> s = (*reopened)->Get(page->sessions[0].session.id());
    ASSERT_TRUE(s.ok()) << s.status();
    EXPECT_EQ(s->session.display_name(), std::to_string(kWriters * kIncrementsPerWriter));
  }
  fs::remove_all(root);
}

TEST(StoreConcurrencyTest, HeavyJobsNeverRunMoreThanTheirLimits) {
  HeavyJobOptions options;
  options.max_running = 2;
  options.max_queued = 64;
  options.max_per_owner = 1;
  HeavyJobs jobs(options);
  std::atomic<int> running{0}, max_seen{0}, granted{0}, refused{0};
  std::atomic<int> per_owner[3] = {0, 0, 0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 6; ++t) {
    threads.emplace_back([&, t] {
      const int owner = t % 3;
      for (int i = 0; i < 30; ++i) {
        absl::StatusOr<HeavyJobs::Slot> slot =
            jobs.Acquire("owner" + std::to_string(owner), [] { return false; });
        if (!slot.ok()) {
          // The owner's share (1) is taken by its other thread: refused, not queued.
          EXPECT_EQ(slot.status().code(), absl::StatusCode::kResourceExhausted) << slot.status();
          ++refused;
          std::this_thread::yield();
          continue;
        }
        ++granted;
        EXPECT_EQ(++per_owner[owner], 1) << "owner" << owner << " holds two slots";
        const int now = ++running;
        int seen = max_seen.load();
        while (now > seen && !max_seen.compare_exchange_weak(seen, now)) {
        }
        EXPECT_LE(jobs.running(), 2);
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        --running;
        --per_owner[owner];
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_LE(max_seen.load(), 2);
  EXPECT_EQ(granted + refused, 6 * 30);
  EXPECT_GT(granted.load(), 0);
  EXPECT_EQ(jobs.running(), 0);
  EXPECT_EQ(jobs.queued(), 0);
}

TEST(StoreConcurrencyTest, MetricsCountEveryObservationWhileRendering) {
  Metrics metrics;
  constexpr int kThreads = 4, kEach = 500;
  std::atomic<bool> done{false};
  std::thread renderer([&] {
    while (!done.load()) {
      const std::string text = metrics.Render({{"inbetween_active_sessions", "Sessions.", 1}});
      EXPECT_THAT(text, ::testing::HasSubstr("inbetween_frames_solved_total"));
    }
  });
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kEach; ++i) {
        metrics.ObserveRpc(t % 2 ? "PutDrawing" : "GetSession", "OK", 1e-3 * i);
        metrics.ObserveStage("optimize", 0.5);
        metrics.CountFrameSolved();
      }
    });
  }
  for (std::thread& t : threads) t.join();
  done = true;
  renderer.join();
  EXPECT_EQ(metrics.frames_solved(), static_cast<uint64_t>(kThreads * kEach));
  const std::string text = metrics.Render({});
  for (const char* method : {"PutDrawing", "GetSession"}) {
    std::smatch m;
    const std::regex counter(std::string("inbetween_rpcs_total\\{code=\"OK\",method=\"") + method +
                             "\"\\} ([0-9]+)");
    ASSERT_TRUE(std::regex_search(text, m, counter)) << text;
    EXPECT_EQ(m[1].str(), std::to_string(kThreads / 2 * kEach));
  }
}

}  // namespace
}  // namespace inbetween::server
