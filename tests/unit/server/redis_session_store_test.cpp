// RedisSessionStore against a real redis-server on a loopback port: two store objects play two
// replicas. Sessions written by one are read (with their multimesh) by the other, a stale write
// is ABORTED, concurrent read-modify-write loops lose no update, listing pages by owner.
#include "server/redis_session_store.h"

#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "solver/core/error_reason.h"
#include "tests/unit/server/redis_fixture.h"
#include "tests/unit/server/store_writers.h"
#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

class RedisSessionStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string binary = FindRedisServer();
    if (binary.empty()) GTEST_SKIP() << "redis-server is not installed";
    redis_ = std::make_unique<RedisProcess>(binary);
    ASSERT_FALSE(redis_->url().empty()) << "could not start " << binary;
  }

  std::unique_ptr<RedisSessionStore> Open(RedisStoreOptions options = {}) {
    auto store = RedisSessionStore::Open(redis_->url(), options);
    EXPECT_TRUE(store.ok()) << store.status();
    return store.ok() ? *std::move(store) : nullptr;
  }

  std::unique_ptr<RedisProcess> redis_;
};

TEST(RedisUrlTest, ParsesHostPortAndDatabase) {
  auto a = ParseRedisUrl("redis://127.0.0.1:6380");
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_EQ(a->host, "127.0.0.1");
  EXPECT_EQ(a->port, 6380);
  EXPECT_EQ(a->db, 0);
  auto b = ParseRedisUrl("redis://[::1]:7000/3");
  ASSERT_TRUE(b.ok()) << b.status();
  EXPECT_EQ(b->host, "::1");
  EXPECT_EQ(b->port, 7000);
  EXPECT_EQ(b->db, 3);
  for (const char* bad : {"redis:/x:1", "127.0.0.1:6379", "redis://host", "redis://:1",
                          "redis://h:0", "redis://h:99999", "redis://h:1/x", "redis://[::1:5"}) {
    auto parsed = ParseRedisUrl(bad);
    EXPECT_EQ(parsed.status().code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(parsed.status().message().find("--store"), std::string::npos) << bad;
  }
}

TEST(RedisUnreachableTest, OpenIsUnavailableNamingTheFlag) {
  const int port = FreeLoopbackPort();  // nothing listens there
  RedisStoreOptions options;
  options.timeout = std::chrono::milliseconds(500);
  auto store = RedisSessionStore::Open("redis://127.0.0.1:" + std::to_string(port), options);
  EXPECT_EQ(store.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_NE(store.status().message().find("--store"), std::string::npos);
}

TEST_F(RedisSessionStoreTest, AReplicaReadsWhatAnotherWroteWithItsMultimesh) {
  auto a = Open();
  auto b = Open();
  auto created = a->Create(StoredSessionState("alice"));
  ASSERT_TRUE(created.ok()) << created.status();
  const std::string id = created->session.id();
  EXPECT_EQ(id.size(), 16u);
  EXPECT_EQ(created->session.version(), 1u);

  auto got = b->Get(id);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->owner, "alice");
  EXPECT_EQ(got->session.display_name(), "squares");
  EXPECT_EQ(got->session.stage(), v1::STAGE_MULTIMESH);
  EXPECT_EQ(got->next_drawing_id, 2u);
  ASSERT_EQ(got->parsed.size(), 1u);
  ASSERT_TRUE(got->multimesh);
  EXPECT_EQ(got->multimesh->triangles.size(), 2u);
  EXPECT_EQ(got->multimesh->shapes[1][2], solver::Point(2, 2));
  EXPECT_EQ(got->multimesh->boundary_loops.size(), 1u);

  // b writes version 2 (b's state moved the vertices, as an optimization would); a, which cached
  // version 1, sees it.
  SessionState moved = *got;
  auto mesh = std::make_shared<solver::Multimesh>(*got->multimesh);
  mesh->shapes[1][2] = solver::Point(3, 3);
  moved.multimesh = mesh;
  moved.session.set_stage(v1::STAGE_OPTIMIZED);
  auto put = b->Put(moved, 1);
  ASSERT_TRUE(put.ok()) << put.status();
  EXPECT_EQ(put->session.version(), 2u);
  EXPECT_EQ(put->session.created_unix_ms(), created->session.created_unix_ms());
  auto seen = a->Get(id);
  ASSERT_TRUE(seen.ok()) << seen.status();
  EXPECT_EQ(seen->session.version(), 2u);
  EXPECT_EQ(seen->session.stage(), v1::STAGE_OPTIMIZED);
  EXPECT_EQ(seen->multimesh->shapes[1][2], solver::Point(3, 3));

  // a's write based on version 1 is stale now.
  auto stale = a->Put(*created, 1);
  EXPECT_EQ(stale.status().code(), absl::StatusCode::kAborted);
  EXPECT_NE(stale.status().message().find("at version 2"), std::string::npos)
      << stale.status().message();
  EXPECT_EQ(b->Get(id)->session.version(), 2u);
}

TEST_F(RedisSessionStoreTest, ConcurrentWritersOnTwoReplicasLoseNoUpdate) {
  auto a = Open();
  auto b = Open();
  SessionState initial = StoredSessionState("");
  initial.session.set_display_name("0");
  auto created = a->Create(initial);
  ASSERT_TRUE(created.ok()) << created.status();
  const std::string id = created->session.id();

  // Each writer increments the counter in display_name with read-modify-write and retries when
  // its version is stale: every increment must land exactly once.
  constexpr int kWriters = 4;
  constexpr int kIncrements = 25;
  std::atomic<int> aborted{0};
  std::vector<std::thread> writers;
  for (int w = 0; w < kWriters; ++w) {
    RedisSessionStore* store = (w % 2 == 0) ? a.get() : b.get();
    writers.emplace_back(
        [store, &id, &aborted] { aborted += IncrementLoop(*store, id, kIncrements); });
  }
  for (std::thread& t : writers) t.join();
  auto final_state = b->Get(id);
  ASSERT_TRUE(final_state.ok());
  EXPECT_EQ(final_state->session.display_name(), std::to_string(kWriters * kIncrements));
  EXPECT_EQ(final_state->session.version(), 1u + kWriters * kIncrements);
  // Not asserted (scheduling decides), but printed: how often the CAS turned a writer back.
  std::printf("stale writes aborted: %d\n", aborted.load());
}

TEST_F(RedisSessionStoreTest, ListsPagesByOwnerCountsAndDeletes) {
  auto a = Open();
  auto b = Open();
  std::vector<std::string> alice;
  for (int i = 0; i < 5; ++i) {
    auto s = (i % 2 ? a : b)->Create(StoredSessionState("alice"));
    ASSERT_TRUE(s.ok()) << s.status();
    alice.push_back(s->session.id());
  }
  ASSERT_TRUE(a->Create(StoredSessionState("bob")).ok());
  EXPECT_EQ(a->Count(), 6u);
  EXPECT_EQ(b->CountOwned("alice"), 5u);
  EXPECT_EQ(b->CountOwned("bob"), 1u);
  EXPECT_EQ(b->CountOwned("carol"), 0u);

  std::vector<std::string> listed;
  std::string token;
  int pages = 0;
  do {
    auto page = (pages % 2 ? a : b)->List(2, token, "alice");
    ASSERT_TRUE(page.ok()) << page.status();
    for (const SessionState& s : page->sessions) {
      EXPECT_EQ(s.owner, "alice");
      EXPECT_EQ(s.session.version(), 1u);
      EXPECT_EQ(s.session.drawings_size(), 0) << "listing returns summaries";
      listed.push_back(s.session.id());
    }
    token = page->next_page_token;
    ++pages;
  } while (!token.empty() && pages < 10);
  EXPECT_EQ(listed, alice) << "creation order, every session once";
  EXPECT_EQ(pages, 3);
  EXPECT_EQ(a->List(2, "x", "alice").status().code(), absl::StatusCode::kInvalidArgument);

  // Delete: stale version ABORTED, then deleted for every replica.
  ASSERT_TRUE(a->Get(alice[0]).ok());  // cached on a
  EXPECT_EQ(b->Delete(alice[0], 7).code(), absl::StatusCode::kAborted);
  EXPECT_TRUE(b->Delete(alice[0], 1).ok());
  EXPECT_EQ(a->Get(alice[0]).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(a->Delete(alice[0], 0).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(a->Put(StoredSessionState("alice"), 1).status().code(), absl::StatusCode::kNotFound);
  EXPECT_TRUE(a->Delete(alice[1], 0).ok());
  EXPECT_EQ(b->CountOwned("alice"), 3u);
  EXPECT_EQ(b->Count(), 4u);
}

TEST_F(RedisSessionStoreTest, ChosenIdsMaxSessionsAndIdleEviction) {
  RedisStoreOptions options;
  options.max_sessions = 2;
  auto a = Open(options);
  SessionState chosen = StoredSessionState("");
  chosen.session.set_id("my-session");
  chosen.session.set_version(7);
  auto created = a->Create(chosen);
  ASSERT_TRUE(created.ok()) << created.status();
  EXPECT_EQ(created->session.version(), 7u) << "a given version is kept (ImportSession)";
  EXPECT_EQ(a->Create(chosen).status().code(), absl::StatusCode::kAlreadyExists);
  ASSERT_TRUE(a->Create(StoredSessionState("")).ok());
  auto full = a->Create(StoredSessionState(""));
  EXPECT_EQ(full.status().code(), absl::StatusCode::kResourceExhausted);

  EXPECT_EQ(a->CachedCount(), 2u);
  EXPECT_EQ(a->EvictIdle(std::chrono::steady_clock::now() - std::chrono::hours(1)), 0u);
  EXPECT_EQ(a->EvictIdle(std::chrono::steady_clock::now() + std::chrono::seconds(1)), 2u);
  EXPECT_EQ(a->CachedCount(), 0u);
  auto reloaded = a->Get("my-session");
  ASSERT_TRUE(reloaded.ok()) << reloaded.status();
  EXPECT_EQ(reloaded->session.version(), 7u);
  ASSERT_TRUE(reloaded->multimesh);
  EXPECT_EQ(a->CachedCount(), 1u);
}

TEST_F(RedisSessionStoreTest, BrokenPooledConnectionsAreReplaced) {
  auto a = Open();
  auto created = a->Create(StoredSessionState(""));
  ASSERT_TRUE(created.ok()) << created.status();
  ASSERT_TRUE(a->Get(created->session.id()).ok());  // the pool holds a connection now
  redis_->KillClients();
  // A read on the dead pooled connection is retried on a new one.
  auto got = a->Get(created->session.id());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(a->Count(), 1u);
  redis_->KillClients();
  // A write starts with a read (owner, created), which replaces the pool; the write then runs.
  auto put = a->Put(*got, 1);
  ASSERT_TRUE(put.ok()) << put.status();
  EXPECT_EQ(put->session.version(), 2u);
}

TEST_F(RedisSessionStoreTest, RedisGoingAwayIsUnavailableNotACrash) {
  auto a = Open();
  auto created = a->Create(StoredSessionState(""));
  ASSERT_TRUE(created.ok());
  redis_->Stop();
  auto got = a->Get(created->session.id());
  EXPECT_EQ(got.status().code(), absl::StatusCode::kUnavailable) << got.status();
  EXPECT_EQ(a->Put(*created, 1).status().code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ(a->Count(), 0u);
}

// One raw command on the test's Redis (CONFIG SET, PTTL, ...): its integer or status text.
std::string Raw(int port, const std::vector<std::string>& args, const std::string& password = "") {
  redisContext* c = redisConnect("127.0.0.1", port);
  std::string out;
  if (c == nullptr || c->err != 0) return "no connection";
  if (!password.empty()) {
    freeReplyObject(redisCommand(c, "AUTH %s", password.c_str()));
  }
  std::vector<const char*> argv;
  std::vector<size_t> lengths;
  for (const std::string& a : args) {
    argv.push_back(a.data());
    lengths.push_back(a.size());
  }
  auto* reply = static_cast<redisReply*>(
      redisCommandArgv(c, static_cast<int>(args.size()), argv.data(), lengths.data()));
  if (reply != nullptr) {
    out = reply->type == REDIS_REPLY_INTEGER ? std::to_string(reply->integer)
                                             : std::string(reply->str ? reply->str : "", reply->len);
    freeReplyObject(reply);
  }
  redisFree(c);
  return out;
}

TEST(RedisUrlTest, CredentialsAreParsedAndNeverRepeated) {
  auto a = ParseRedisUrl("redis://:s3cret@127.0.0.1:6380/2");
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_EQ(a->user, "");
  EXPECT_EQ(a->password, "s3cret");
  EXPECT_EQ(a->host, "127.0.0.1");
  EXPECT_EQ(a->db, 2);
  auto b = ParseRedisUrl("redis://app:p@ss@[::1]:7000");
  ASSERT_TRUE(b.ok()) << b.status();
  EXPECT_EQ(b->user, "app");
  EXPECT_EQ(b->password, "p@ss");
  EXPECT_EQ(b->host, "::1");
  EXPECT_EQ(RedactRedisUrl("redis://app:p@ss@host:1/2"), "redis://***@host:1/2");
  EXPECT_EQ(RedactRedisUrl("redis://host:1"), "redis://host:1");
  auto bad = ParseRedisUrl("redis://:s3cret@host");
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(bad.status().message().find("s3cret"), std::string::npos) << bad.status();
  auto no_colon = ParseRedisUrl("redis://s3cret@host:1");
  EXPECT_EQ(no_colon.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(no_colon.status().message().find("s3cret"), std::string::npos) << no_colon.status();
}

TEST_F(RedisSessionStoreTest, APasswordIsSentAndAMissingOneIsNamed) {
  ASSERT_EQ(Raw(redis_->port(), {"CONFIG", "SET", "requirepass", "pa ss"}), "OK");
  RedisStoreOptions options;
  options.timeout = std::chrono::milliseconds(2000);
  auto none = RedisSessionStore::Open(redis_->url(), options);
  EXPECT_EQ(none.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_NE(none.status().message().find("--redis-password-file"), std::string::npos)
      << none.status();
  options.password = "wrong";
  auto wrong = RedisSessionStore::Open(redis_->url(), options);
  EXPECT_EQ(wrong.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_NE(wrong.status().message().find("AUTH"), std::string::npos) << wrong.status();
  EXPECT_EQ(wrong.status().message().find("wrong"), std::string::npos) << wrong.status();
  options.password = "pa ss";
  auto right = RedisSessionStore::Open(redis_->url(), options);
  ASSERT_TRUE(right.ok()) << right.status();
  ASSERT_TRUE((*right)->Create(StoredSessionState("alice")).ok());
  // The same password in the URL.
  const std::string url = "redis://:pa ss@127.0.0.1:" + std::to_string(redis_->port());
  auto by_url = RedisSessionStore::Open(url);
  ASSERT_TRUE(by_url.ok()) << by_url.status();
  EXPECT_EQ((*by_url)->Count(), 1u);
  Raw(redis_->port(), {"CONFIG", "SET", "requirepass", ""}, "pa ss");
}

TEST_F(RedisSessionStoreTest, SessionsExpireAfterTheirLastUseAndLeaveNoIndexEntries) {
  RedisStoreOptions options;
  options.session_ttl = std::chrono::milliseconds(60'000);
  auto a = Open(options);
  auto created = a->Create(StoredSessionState("alice"));
  ASSERT_TRUE(created.ok()) << created.status();
  const std::string key = "inbetween:s:" + created->session.id();
  const int64_t fresh = std::stoll(Raw(redis_->port(), {"PTTL", key}));
  EXPECT_GT(fresh, 50'000);
  EXPECT_LE(fresh, 60'000);
  // A read is a use: the TTL starts again.
  ASSERT_EQ(Raw(redis_->port(), {"PEXPIRE", key, "5000"}), "1");
  ASSERT_TRUE(a->Get(created->session.id()).ok());
  EXPECT_GT(std::stoll(Raw(redis_->port(), {"PTTL", key})), 50'000);
  // ... and so is a write.
  ASSERT_EQ(Raw(redis_->port(), {"PEXPIRE", key, "5000"}), "1");
  ASSERT_TRUE(a->Put(*created, 1).ok());
  EXPECT_GT(std::stoll(Raw(redis_->port(), {"PTTL", key})), 50'000);

  // An expired session is gone, and counting or creating drops its index entries.
  RedisStoreOptions brief;
  brief.session_ttl = std::chrono::milliseconds(200);
  auto c = Open(brief);
  auto gone = c->Create(StoredSessionState("alice"));
  ASSERT_TRUE(gone.ok());
  EXPECT_EQ(a->CountOwned("alice"), 2u);
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  EXPECT_EQ(c->Get(gone->session.id()).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(a->CountOwned("alice"), 1u);
  EXPECT_EQ(a->Count(), 1u);
  EXPECT_EQ(Raw(redis_->port(), {"HEXISTS", "inbetween:owner", gone->session.id()}), "0");
  EXPECT_EQ(Raw(redis_->port(), {"ZCARD", "inbetween:exp"}), "1");
  auto page = a->List(10, "", "alice");
  ASSERT_TRUE(page.ok());
  ASSERT_EQ(page->sessions.size(), 1u);
  EXPECT_EQ(page->sessions[0].session.id(), created->session.id());
  const auto& other = page->sessions[0];

  // TTL 0: sessions are kept (an existing TTL is removed on the next use).
  RedisStoreOptions keep;
  auto b = Open(keep);
  ASSERT_TRUE(b->Get(other.session.id()).ok());
  EXPECT_EQ(Raw(redis_->port(), {"PTTL", "inbetween:s:" + other.session.id()}), "-1");
}

TEST_F(RedisSessionStoreTest, AFullRedisRefusesNewSessionsButKeepsServingOld) {
  auto a = Open();
  auto first = a->Create(StoredSessionState("alice"));
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_EQ(Raw(redis_->port(), {"CONFIG", "SET", "maxmemory-policy", "noeviction"}), "OK");
  ASSERT_EQ(Raw(redis_->port(), {"CONFIG", "SET", "maxmemory", "1"}), "OK");  // always over
  auto refused = a->Create(StoredSessionState("alice"));
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kResourceExhausted) << refused.status();
  EXPECT_EQ(solver::ErrorReason(refused.status()), solver::kReasonStoreFull);
  EXPECT_NE(refused.status().message().find("maxmemory"), std::string::npos);
  EXPECT_EQ(a->Put(*first, 1).status().code(), absl::StatusCode::kResourceExhausted);
  auto read = a->Get(first->session.id());  // reads (and their TTL refresh) still work
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->session.version(), 1u);
  EXPECT_EQ(a->Count(), 1u);
  ASSERT_EQ(Raw(redis_->port(), {"CONFIG", "SET", "maxmemory", "0"}), "OK");
  EXPECT_TRUE(a->Create(StoredSessionState("alice")).ok());
}

}  // namespace
}  // namespace inbetween::server::testing
