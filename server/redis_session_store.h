// Sessions in Redis (--store redis://HOST:PORT[/DB]) so that several inbetween-server replicas
// share them: a session is loaded lazily on whichever replica gets a call for it, and cached
// there while its version in Redis is unchanged.
//
// Layout (prefix "inbetween:"): hash s:<id> {v: version, o: owner, c: created ms, q: sequence,
// m: summary (Session proto), d: snapshot (session_snapshot.h: drawings, multimesh, optimized
// positions, stats)}; sorted sets all and own:<owner> (id by sequence) for counting and listing;
// counter seq. Create, Put and Delete are Lua scripts, so the version check and the write are
// one atomic step in Redis: of two replicas writing the same version, one gets ABORTED.
//
// Retention: with a session TTL each s:<id> expires that long after its last use (create, write,
// read); sorted set exp (id by expiry ms, a lower bound) and hash owner (id -> owner) let the
// scripts that count or create drop an expired session's index entries (a bounded sweep).
// Memory: Redis should run with maxmemory and maxmemory-policy noeviction, so no live session is
// evicted silently; a write Redis refuses for memory is RESOURCE_EXHAUSTED (reason STORE_FULL),
// while reads keep working.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include "server/session_store.h"

struct redisContext;

namespace inbetween::server {

struct RedisStoreOptions {
  size_t max_sessions = 10000;  // in the whole Redis database (all replicas)
  size_t max_cached = 256;      // sessions cached in this process (least recently used dropped)
  std::chrono::milliseconds timeout{5000};  // connect and per-command timeout
  // A session expires this long after its last use; 0 = never (--session-ttl-seconds).
  std::chrono::milliseconds session_ttl{0};
  // AUTH password (--redis-password-file); when set it wins over a password in the URL.
  std::string password;
};

struct RedisAddress {
  std::string host;
  int port = 6379;
  int db = 0;
  std::string user;      // ACL user; empty = the default user
  std::string password;  // empty = no AUTH
};

// "redis://[[USER]:PASSWORD@]HOST:PORT[/DB]" (HOST may be [IPv6]); INVALID_ARGUMENT naming
// --store otherwise. Error messages never repeat the password.
absl::StatusOr<RedisAddress> ParseRedisUrl(absl::string_view url);
// `url` with any user and password replaced by "***", for logs and messages.
std::string RedactRedisUrl(absl::string_view url);

class RedisSessionStore final : public SessionStore {
 public:
  // Connects (and PINGs) once; UNAVAILABLE naming --store when Redis cannot be reached.
  static absl::StatusOr<std::unique_ptr<RedisSessionStore>> Open(absl::string_view url,
                                                                 RedisStoreOptions options = {});
  ~RedisSessionStore() override;

  absl::StatusOr<SessionState> Get(absl::string_view id) const override;
  absl::StatusOr<SessionState> Create(SessionState state) override;
  absl::StatusOr<SessionState> Put(SessionState state, uint64_t expected_version) override;
  absl::StatusOr<SessionState> PutSameVersion(SessionState state,
                                              uint64_t expected_version) override;
  absl::StatusOr<SessionState> GetLatest(absl::string_view id) const override;
  absl::StatusOr<SessionPage> List(size_t page_size, absl::string_view page_token,
                                   absl::string_view owner) const override;
  size_t CountOwned(absl::string_view owner) const override;
  size_t Count() const override;
  absl::Status Delete(absl::string_view id, uint64_t expected_version) override;
  size_t EvictIdle(std::chrono::steady_clock::time_point idle_before) override;
  size_t CachedCount() const override;

  class Reply;  // an owned redisReply

 private:
  absl::StatusOr<SessionState> Load(absl::string_view id, bool use_cache) const;
  absl::StatusOr<SessionState> Replace(SessionState state, uint64_t expected_version,
                                       bool same_version);

  struct Cached {
    SessionState state;
    uint64_t last_used = 0;
    std::chrono::steady_clock::time_point used_at;
  };

  RedisSessionStore(RedisAddress address, RedisStoreOptions options);
  // Runs one command on a pooled connection (binary-safe arguments). UNAVAILABLE on connection
  // errors (the pool is dropped; an idempotent command is tried once more on a new connection),
  // INTERNAL on a Redis error reply.
  absl::StatusOr<Reply> Command(const std::vector<std::string>& args, bool idempotent = true) const;
  absl::StatusOr<redisContext*> Connect() const;
  // "session store: redis HOST:PORT" (no credentials), the start of every message.
  std::string Where() const;
  void Remember(const SessionState& state) const;
  std::string TtlArgument() const { return std::to_string(options_.session_ttl.count()); }

  const RedisAddress address_;
  const RedisStoreOptions options_;
  mutable std::mutex pool_mutex_;
  mutable std::vector<redisContext*> idle_;
  mutable std::mutex cache_mutex_;
  mutable std::map<std::string, Cached, std::less<>> cache_;
  mutable uint64_t clock_ = 0;
  mutable std::mutex rng_mutex_;
  mutable std::mt19937_64 rng_;
};

}  // namespace inbetween::server
