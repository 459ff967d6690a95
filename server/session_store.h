// Session storage behind one interface (memory, directory snapshots, Redis) with optimistic
// locking: every mutation increments the version, a stale expected version is ABORTED.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/session_state.h"

namespace inbetween::server {

// One page of List: states in deterministic order (creation order, then id).
struct SessionPage {
  std::vector<SessionState> sessions;
  std::string next_page_token;  // empty = last page
  uint64_t last_sequence = 0;   // the store's position of the last session on the page
};

class SessionStore {
 public:
  virtual ~SessionStore() = default;

  // A copy of the session, or NOT_FOUND.
  virtual absl::StatusOr<SessionState> Get(absl::string_view id) const = 0;

  // Inserts a new session. An empty state.session.id gets a fresh random id; a taken id is
  // ALREADY_EXISTS. Sets version (>= 1; a given version is kept), created (if unset) and
  // updated times. Returns the stored state.
  virtual absl::StatusOr<SessionState> Create(SessionState state) = 0;

  // Replaces the session with id state.session.id if its version is expected_version (else
  // ABORTED, or NOT_FOUND), then increments the version and sets the updated time. The caller's
  // version and created fields are ignored. Returns the stored state.
  virtual absl::StatusOr<SessionState> Put(SessionState state, uint64_t expected_version) = 0;

  // Like Put, but the version stays expected_version: for data derived from that version that
  // no other call reads (OptimizeComesh's checkpoint), so the write moves no client's version
  // on. Another replica may keep serving its cached copy of that version; GetLatest reads past
  // such caches.
  virtual absl::StatusOr<SessionState> PutSameVersion(SessionState state,
                                                      uint64_t expected_version) = 0;
  // Like Get, but never a cached copy that another replica's PutSameVersion made stale.
  virtual absl::StatusOr<SessionState> GetLatest(absl::string_view id) const { return Get(id); }

  // Up to page_size sessions of `owner` after page_token (from a previous page; empty = the
  // first page).
  virtual absl::StatusOr<SessionPage> List(size_t page_size, absl::string_view page_token,
                                           absl::string_view owner) const = 0;

  // Number of sessions of `owner` (for the sessions-per-token limit) and in total.
  virtual size_t CountOwned(absl::string_view owner) const = 0;
  virtual size_t Count() const = 0;

  // Deletes the session; expected_version 0 deletes whatever the version.
  virtual absl::Status Delete(absl::string_view id, uint64_t expected_version) = 0;

  // Stores that keep a durable copy (dir, Redis) cache loaded sessions in memory; this drops
  // the cached sessions not used since `idle_before` (they reload on next use) and returns how
  // many it dropped. The memory store has nowhere to evict to and keeps everything.
  virtual size_t EvictIdle(std::chrono::steady_clock::time_point idle_before) {
    (void)idle_before;
    return 0;
  }
  // Sessions held in memory (all of them for the memory store).
  virtual size_t CachedCount() const { return Count(); }
};

// The ABORTED status of a stale expected version, worded the same by every store.
// (NOT_FOUND is worded by NotFoundError below.)
absl::Status StaleVersionError(absl::string_view id, uint64_t current, uint64_t expected);

absl::Status SessionNotFoundError(absl::string_view id);

// The RESOURCE_EXHAUSTED of a full store, naming the flag that sets the limit, worded the same by
// every store.
absl::Status SessionLimitError(size_t max_sessions);

// Parses a List page token (a sequence number); INVALID_ARGUMENT if it is not one.
absl::StatusOr<uint64_t> ParsePageToken(absl::string_view page_token);

// The version check of Put (exact match) and Delete (expected 0 = any version).
absl::Status CheckPutVersion(absl::string_view id, uint64_t current, uint64_t expected);
absl::Status CheckDeleteVersion(absl::string_view id, uint64_t current, uint64_t expected);

// Create's stamping: sets the id, version 1 unless given, created (if unset) and updated times.
void StampCreated(SessionState& state, const std::string& id);
// Put's stamping: the version after `current`'s (PutSameVersion: `current`'s), `current`'s
// created time, updated = now.
void StampPut(SessionState& state, const inbetween::v1::Session& current,
              bool same_version = false);

// One List page over an index ordered by sequence (creation order), shared by every store.
// `listed(id, &state)` fills the state to list and returns true, or returns false for sessions
// of other owners. The page token is the sequence of the last listed session, so pages stay
// consistent while sessions are created and deleted in between.
absl::StatusOr<SessionPage> PageBySequence(
    const std::map<uint64_t, std::string>& by_sequence, size_t page_size, uint64_t after,
    const std::function<bool(const std::string& id, SessionState* state)>& listed);

// A fresh random session id (16 lowercase hex digits).
std::string RandomSessionId(std::mt19937_64& rng);

// Milliseconds since the Unix epoch (wall clock).
int64_t NowUnixMs();

// Process-local store; a mutex guards the map (callers copy states out and compute unlocked).
class MemorySessionStore final : public SessionStore {
 public:
  explicit MemorySessionStore(size_t max_sessions = 10000);

  absl::StatusOr<SessionState> Get(absl::string_view id) const override;
  absl::StatusOr<SessionState> Create(SessionState state) override;
  absl::StatusOr<SessionState> Put(SessionState state, uint64_t expected_version) override;
  absl::StatusOr<SessionState> PutSameVersion(SessionState state,
                                              uint64_t expected_version) override;
  absl::StatusOr<SessionPage> List(size_t page_size, absl::string_view page_token,
                                   absl::string_view owner) const override;
  size_t CountOwned(absl::string_view owner) const override;
  size_t Count() const override;
  absl::Status Delete(absl::string_view id, uint64_t expected_version) override;

 private:
  absl::StatusOr<SessionState> Replace(SessionState state, uint64_t expected_version,
                                       bool same_version);

  struct Entry {
    uint64_t sequence;  // insertion order; the List order and the page token
    SessionState state;
  };

  std::string NewIdLocked();

  const size_t max_sessions_;
  mutable std::mutex mutex_;
  std::map<std::string, Entry, std::less<>> by_id_;
  std::map<uint64_t, std::string> by_sequence_;
  uint64_t next_sequence_ = 1;
  std::mt19937_64 rng_;
};

}  // namespace inbetween::server
