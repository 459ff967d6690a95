// DirSessionStore: an index in memory, snapshots on disk. All mutations hold the store's mutex
// while they write, so a version is on disk (fsynced) before anyone can see it.
#include "server/dir_session_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/session_snapshot.h"

namespace inbetween::server {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kSuffix = ".snap";

std::string VersionFile(uint64_t version) { return absl::StrFormat("%020u.snap", version); }

absl::Status Errno(absl::string_view what, const fs::path& path) {
  return absl::InternalError(
      absl::StrCat("session store: ", what, " ", path.string(), ": ", std::strerror(errno)));
}

absl::Status FsyncPath(const fs::path& path, int flags) {
  const int fd = open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return Errno("cannot open", path);
  const int rc = fsync(fd);
  close(fd);
  if (rc != 0) return Errno("cannot fsync", path);
  return absl::OkStatus();
}

// Writes `bytes` to dir/name atomically: temp file in the same directory, fsync, rename, fsync
// of the directory.
absl::Status WriteAtomically(const fs::path& dir, const std::string& name,
                             const std::string& bytes) {
  const fs::path tmp = dir / absl::StrCat(".tmp-", name, "-", getpid());
  const int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return Errno("cannot create", tmp);
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      absl::Status s = Errno("cannot write", tmp);
      close(fd);
      unlink(tmp.c_str());
      return s;
    }
    written += static_cast<size_t>(n);
  }
  if (fsync(fd) != 0) {
    absl::Status s = Errno("cannot fsync", tmp);
    close(fd);
    unlink(tmp.c_str());
    return s;
  }
  close(fd);
  if (rename(tmp.c_str(), (dir / name).c_str()) != 0) {
    absl::Status s = Errno("cannot rename", tmp);
    unlink(tmp.c_str());
    return s;
  }
  return FsyncPath(dir, O_RDONLY | O_DIRECTORY);
}

absl::StatusOr<std::string> ReadFile(const fs::path& path, size_t max_bytes = SIZE_MAX) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Errno("cannot read", path);
  std::string out;
  if (max_bytes == SIZE_MAX) {
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  out.resize(max_bytes);
  in.read(out.data(), static_cast<std::streamsize>(max_bytes));
  out.resize(static_cast<size_t>(in.gcount()));
  return out;
}

// Snapshot files of a session directory, newest first.
std::vector<std::pair<uint64_t, fs::path>> Snapshots(const fs::path& dir) {
  std::vector<std::pair<uint64_t, fs::path>> out;
  std::error_code error;
  for (const fs::directory_entry& file : fs::directory_iterator(dir, error)) {
    const std::string name = file.path().filename().string();
    if (name.size() != 20 + kSuffix.size() || !name.ends_with(kSuffix)) continue;
    uint64_t version = 0;
    if (std::sscanf(name.c_str(), "%20lu", &version) != 1) continue;
    out.emplace_back(version, file.path());
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  return out;
}

}  // namespace

DirSessionStore::DirSessionStore(fs::path root, DirStoreOptions options)
    : root_(std::move(root)), options_(options), rng_(std::random_device{}()) {}

absl::StatusOr<std::unique_ptr<DirSessionStore>> DirSessionStore::Open(const std::string& path,
                                                                       DirStoreOptions options) {
  if (path.empty()) return absl::InvalidArgumentError("--store dir:PATH needs a PATH");
  std::error_code error;
  fs::create_directories(fs::path(path) / "sessions", error);
  fs::create_directories(fs::path(path) / "trash", error);
  if (error) {
    return absl::InvalidArgumentError(
        absl::StrCat("--store: cannot create '", path, "': ", error.message()));
  }
  std::unique_ptr<DirSessionStore> store(new DirSessionStore(fs::path(path), options));
  // Finish interrupted deletions, then index every session by its newest readable snapshot.
  fs::remove_all(store->root_ / "trash", error);
  fs::create_directories(store->root_ / "trash", error);
  struct Found {
    std::string id;
    SnapshotHead head;
  };
  std::vector<Found> found;
  for (const fs::directory_entry& dir : fs::directory_iterator(store->root_ / "sessions", error)) {
    if (!dir.is_directory()) continue;
    for (const fs::directory_entry& file : fs::directory_iterator(dir.path(), error)) {
      if (file.path().filename().string().starts_with(".tmp-")) fs::remove(file.path(), error);
    }
    for (const auto& [version, file] : Snapshots(dir.path())) {
      // The head is small; 64 KiB covers owner + summary with a long display name.
      absl::StatusOr<std::string> bytes = ReadFile(file, 64 * 1024);
      if (!bytes.ok()) continue;
      absl::StatusOr<SnapshotHead> head = DecodeSnapshotHead(*bytes, file.string());
      if (!head.ok() || head->summary.version() != version) continue;
      found.push_back({dir.path().filename().string(), *std::move(head)});
      break;
    }
  }
  // Listing order: creation time, then id (the sequence numbers are per process).
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    return std::make_pair(a.head.summary.created_unix_ms(), a.id) <
           std::make_pair(b.head.summary.created_unix_ms(), b.id);
  });
  for (Found& f : found) {
    Entry entry;
    entry.sequence = store->next_sequence_++;
    entry.owner = std::move(f.head.owner);
    entry.summary = std::move(f.head.summary);
    store->by_sequence_.emplace(entry.sequence, f.id);
    store->by_id_.emplace(f.id, std::move(entry));
  }
  return store;
}

fs::path DirSessionStore::SessionDir(absl::string_view id) const {
  return root_ / "sessions" / std::string(id);
}

absl::Status DirSessionStore::WriteSnapshotLocked(const SessionState& state) {
  const fs::path dir = SessionDir(state.session.id());
  std::error_code error;
  if (!fs::exists(dir, error)) {
    if (!fs::create_directory(dir, error)) {
      return absl::InternalError(
          absl::StrCat("session store: cannot create ", dir.string(), ": ", error.message()));
    }
    if (absl::Status s = FsyncPath(root_ / "sessions", O_RDONLY | O_DIRECTORY); !s.ok()) return s;
  }
  if (absl::Status s =
          WriteAtomically(dir, VersionFile(state.session.version()), EncodeSnapshot(state));
      !s.ok()) {
    return s;
  }
  // Old versions go only after the new one is durable.
  const auto snapshots = Snapshots(dir);
  for (size_t i = std::max(1, options_.keep_versions); i < snapshots.size(); ++i) {
    fs::remove(snapshots[i].second, error);
  }
  return absl::OkStatus();
}

absl::StatusOr<SessionState*> DirSessionStore::LoadLocked(Entry& entry) const {
  entry.last_used = ++clock_;
  entry.used_at = std::chrono::steady_clock::now();
  if (entry.cached) return &*entry.cached;
  const fs::path file = SessionDir(entry.summary.id()) / VersionFile(entry.summary.version());
  absl::StatusOr<std::string> bytes = ReadFile(file);
  if (!bytes.ok()) return bytes.status();
  absl::StatusOr<SessionState> state = DecodeSnapshot(*bytes, file.string());
  if (!state.ok()) return state.status();
  entry.cached = *std::move(state);
  TrimCacheLocked();
  return &*entry.cached;
}

void DirSessionStore::TrimCacheLocked() const {
  size_t cached = 0;
  for (const auto& [id, entry] : by_id_) cached += entry.cached.has_value();
  while (cached > std::max<size_t>(1, options_.max_cached)) {
    Entry* oldest = nullptr;
    for (auto& [id, entry] : by_id_) {
      if (entry.cached && (oldest == nullptr || entry.last_used < oldest->last_used)) {
        oldest = &entry;
      }
    }
    oldest->cached.reset();  // still on disk
    --cached;
  }
}

size_t DirSessionStore::EvictIdle(std::chrono::steady_clock::time_point idle_before) {
  std::lock_guard lock(mutex_);
  size_t evicted = 0;
  for (auto& [id, entry] : by_id_) {
    if (entry.cached && entry.used_at < idle_before) {
      entry.cached.reset();  // the newest snapshot on disk is this version
      ++evicted;
    }
  }
  return evicted;
}

size_t DirSessionStore::CachedCount() const {
  std::lock_guard lock(mutex_);
  size_t n = 0;
  for (const auto& [id, entry] : by_id_) n += entry.cached.has_value();
  return n;
}

absl::StatusOr<SessionState> DirSessionStore::Get(absl::string_view id) const {
  std::lock_guard lock(mutex_);
  auto it = by_id_.find(id);
  if (it == by_id_.end()) return SessionNotFoundError(id);
  absl::StatusOr<SessionState*> state = LoadLocked(it->second);
  if (!state.ok()) return state.status();
  return **state;
}

absl::StatusOr<SessionState> DirSessionStore::Create(SessionState state) {
  std::lock_guard lock(mutex_);
  if (by_id_.size() >= options_.max_sessions) {
    return SessionLimitError(options_.max_sessions);
  }
  std::string id = state.session.id();
  if (id.empty()) {
    do {
      id = RandomSessionId(rng_);
    } while (by_id_.contains(id));
  } else if (by_id_.contains(id)) {
    return absl::AlreadyExistsError(absl::StrCat("session ", id, " already exists"));
  }
  StampCreated(state, id);
  if (absl::Status s = WriteSnapshotLocked(state); !s.ok()) return s;
  Entry entry;
  entry.sequence = next_sequence_++;
  entry.owner = state.owner;
  entry.summary = SessionSummary(state.session);
  entry.cached = state;
  entry.last_used = ++clock_;
  entry.used_at = std::chrono::steady_clock::now();
  by_sequence_.emplace(entry.sequence, id);
  by_id_.emplace(id, std::move(entry));
  TrimCacheLocked();
  return state;
}

absl::StatusOr<SessionState> DirSessionStore::Put(SessionState state, uint64_t expected_version) {
  return Replace(std::move(state), expected_version, /*same_version=*/false);
}

// The same version's snapshot file is replaced atomically, like a new version's is written.
absl::StatusOr<SessionState> DirSessionStore::PutSameVersion(SessionState state,
                                                             uint64_t expected_version) {
  return Replace(std::move(state), expected_version, /*same_version=*/true);
}

absl::StatusOr<SessionState> DirSessionStore::Replace(SessionState state, uint64_t expected_version,
                                                      bool same_version) {
  std::lock_guard lock(mutex_);
  auto it = by_id_.find(state.session.id());
  if (it == by_id_.end()) return SessionNotFoundError(state.session.id());
  Entry& entry = it->second;
  if (auto s = CheckPutVersion(entry.summary.id(), entry.summary.version(), expected_version);
      !s.ok()) {
    return s;
  }
  StampPut(state, entry.summary, same_version);
  state.owner = entry.owner;
  if (absl::Status s = WriteSnapshotLocked(state); !s.ok()) return s;
  entry.summary = SessionSummary(state.session);
  entry.cached = state;
  entry.last_used = ++clock_;
  entry.used_at = std::chrono::steady_clock::now();
  TrimCacheLocked();
  return state;
}

absl::StatusOr<SessionPage> DirSessionStore::List(size_t page_size, absl::string_view page_token,
                                                  absl::string_view owner) const {
  absl::StatusOr<uint64_t> after = ParsePageToken(page_token);
  if (!after.ok()) return after.status();
  std::lock_guard lock(mutex_);
  // Summaries only: listing does not load sessions.
  return PageBySequence(by_sequence_, page_size, *after,
                        [&](const std::string& id, SessionState* state) {
                          const Entry& entry = by_id_.find(id)->second;
                          if (entry.owner != owner) return false;
                          state->session = entry.summary;
                          state->owner = entry.owner;
                          return true;
                        });
}

size_t DirSessionStore::CountOwned(absl::string_view owner) const {
  std::lock_guard lock(mutex_);
  size_t n = 0;
  for (const auto& [id, entry] : by_id_) n += entry.owner == owner;
  return n;
}

size_t DirSessionStore::Count() const {
  std::lock_guard lock(mutex_);
  return by_id_.size();
}

absl::Status DirSessionStore::Delete(absl::string_view id, uint64_t expected_version) {
  std::lock_guard lock(mutex_);
  auto it = by_id_.find(id);
  if (it == by_id_.end()) return SessionNotFoundError(id);
  if (auto s = CheckDeleteVersion(id, it->second.summary.version(), expected_version); !s.ok()) {
    return s;
  }
  // One rename makes the deletion durable; the files go afterwards (or at the next start).
  const fs::path trash = root_ / "trash" / absl::StrCat(id, "-", it->second.sequence);
  if (rename(SessionDir(id).c_str(), trash.c_str()) != 0)
    return Errno("cannot delete", SessionDir(id));
  if (absl::Status s = FsyncPath(root_ / "sessions", O_RDONLY | O_DIRECTORY); !s.ok()) return s;
  std::error_code error;
  fs::remove_all(trash, error);
  by_sequence_.erase(it->second.sequence);
  by_id_.erase(it);
  return absl::OkStatus();
}

}  // namespace inbetween::server
