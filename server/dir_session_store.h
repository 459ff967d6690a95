// Sessions persisted to a directory (--store dir:PATH): every version of a session is written as
// one snapshot file (session_snapshot.h), atomically (temp file, fsync, rename, fsync of the
// directory), so a session survives kill -9 at any point with its last acknowledged version.
// Layout: PATH/sessions/<id>/<version, 20 digits>.snap; the newest few versions are kept.
// Start-up reads only each session's head (owner, summary); the rest is loaded on first use and
// cached (at most max_cached sessions in memory, least recently used dropped first).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>

#include "server/session_store.h"

namespace inbetween::server {

struct DirStoreOptions {
  size_t max_sessions = 10000;
  size_t max_cached = 256;
  int keep_versions = 2;  // snapshots kept per session (>= 1)
};

class DirSessionStore final : public SessionStore {
 public:
  // Creates PATH if needed and indexes the sessions in it. Errors name the flag (--store).
  static absl::StatusOr<std::unique_ptr<DirSessionStore>> Open(const std::string& path,
                                                               DirStoreOptions options = {});

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
  size_t EvictIdle(std::chrono::steady_clock::time_point idle_before) override;
  size_t CachedCount() const override;

 private:
  absl::StatusOr<SessionState> Replace(SessionState state, uint64_t expected_version,
                                       bool same_version);

  struct Entry {
    uint64_t sequence = 0;
    std::string owner;
    inbetween::v1::Session summary;
    std::optional<SessionState> cached;  // mutable through the const Get (a cache)
    uint64_t last_used = 0;
    std::chrono::steady_clock::time_point used_at;  // for EvictIdle
  };

  DirSessionStore(std::filesystem::path root, DirStoreOptions options);
  std::filesystem::path SessionDir(absl::string_view id) const;
  absl::Status WriteSnapshotLocked(const SessionState& state);
  absl::StatusOr<SessionState*> LoadLocked(Entry& entry) const;
  void TrimCacheLocked() const;

  const std::filesystem::path root_;
  const DirStoreOptions options_;
  mutable std::mutex mutex_;
  mutable std::map<std::string, Entry, std::less<>> by_id_;
  std::map<uint64_t, std::string> by_sequence_;
  uint64_t next_sequence_ = 1;
  mutable uint64_t clock_ = 0;
  std::mt19937_64 rng_;
};

}  // namespace inbetween::server
