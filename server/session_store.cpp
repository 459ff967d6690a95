// MemorySessionStore: sessions in a map under one mutex; List pages by insertion sequence.
#include "server/session_store.h"

#include <charconv>
#include <chrono>
#include <iterator>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/core/error_reason.h"

namespace inbetween::server {

absl::Status StaleVersionError(absl::string_view id, uint64_t current, uint64_t expected) {
  return absl::AbortedError(
      absl::StrCat("session ", id, " is at version ", current, ", request expected ", expected));
}

int64_t NowUnixMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

absl::Status SessionNotFoundError(absl::string_view id) {
  return absl::NotFoundError(absl::StrCat("session ", id, " not found"));
}

absl::Status SessionLimitError(size_t max_sessions) {
  return solver::WithReason(
      absl::ResourceExhaustedError(absl::StrCat("the server holds the maximum of ", max_sessions,
                                                " sessions (--max-sessions ", max_sessions,
                                                "); delete some first")),
      solver::kReasonSessionLimit);
}

absl::StatusOr<uint64_t> ParsePageToken(absl::string_view page_token) {
  uint64_t after = 0;
  if (page_token.empty()) return after;
  auto [end, error] =
      std::from_chars(page_token.data(), page_token.data() + page_token.size(), after);
  if (error != std::errc() || end != page_token.data() + page_token.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("page_token '", page_token, "' is not a token from ListSessions"));
  }
  return after;
}

std::string RandomSessionId(std::mt19937_64& rng) {
  static constexpr char kHex[] = "0123456789abcdef";
  uint64_t bits = rng();
  std::string id(16, '0');
  for (char& c : id) {
    c = kHex[bits & 0xf];
    bits >>= 4;
  }
  return id;
}

absl::Status CheckPutVersion(absl::string_view id, uint64_t current, uint64_t expected) {
  if (current != expected) return StaleVersionError(id, current, expected);
  return absl::OkStatus();
}

absl::Status CheckDeleteVersion(absl::string_view id, uint64_t current, uint64_t expected) {
  if (expected == 0) return absl::OkStatus();
  return CheckPutVersion(id, current, expected);
}

void StampCreated(SessionState& state, const std::string& id) {
  const int64_t now = NowUnixMs();
  state.session.set_id(id);
  if (state.session.version() == 0) state.session.set_version(1);
  if (state.session.created_unix_ms() == 0) state.session.set_created_unix_ms(now);
  state.session.set_updated_unix_ms(now);
}

void StampPut(SessionState& state, const inbetween::v1::Session& current, bool same_version) {
  state.session.set_version(current.version() + (same_version ? 0 : 1));
  state.session.set_created_unix_ms(current.created_unix_ms());
  state.session.set_updated_unix_ms(NowUnixMs());
}

absl::StatusOr<SessionPage> PageBySequence(
    const std::map<uint64_t, std::string>& by_sequence, size_t page_size, uint64_t after,
    const std::function<bool(const std::string& id, SessionState* state)>& listed) {
  SessionPage page;
  SessionState state;
  for (auto it = by_sequence.upper_bound(after); it != by_sequence.end(); ++it) {
    if (!listed(it->second, &state)) continue;
    if (page.sessions.size() == page_size) {
      page.next_page_token = absl::StrCat(page.last_sequence);
      break;
    }
    page.sessions.push_back(std::move(state));
    state = SessionState();
    page.last_sequence = it->first;
  }
  return page;
}

namespace {

absl::Status NotFound(absl::string_view id) { return SessionNotFoundError(id); }

}  // namespace

MemorySessionStore::MemorySessionStore(size_t max_sessions)
    : max_sessions_(max_sessions), rng_(std::random_device{}()) {}

std::string MemorySessionStore::NewIdLocked() {
  while (true) {
    std::string id = RandomSessionId(rng_);
    if (!by_id_.contains(id)) return id;
  }
}

absl::StatusOr<SessionState> MemorySessionStore::Get(absl::string_view id) const {
  std::lock_guard lock(mutex_);
  auto it = by_id_.find(id);
  if (it == by_id_.end()) return NotFound(id);
  return it->second.state;
}

absl::StatusOr<SessionState> MemorySessionStore::Create(SessionState state) {
  std::lock_guard lock(mutex_);
  if (by_id_.size() >= max_sessions_) {
    return SessionLimitError(max_sessions_);
  }
  std::string id = state.session.id();
  if (id.empty()) {
    id = NewIdLocked();
  } else if (by_id_.contains(id)) {
    return absl::AlreadyExistsError(absl::StrCat("session ", id, " already exists"));
  }
  StampCreated(state, id);
  const uint64_t sequence = next_sequence_++;
  by_sequence_.emplace(sequence, id);
  auto [it, inserted] = by_id_.emplace(id, Entry{sequence, std::move(state)});
  return it->second.state;
}

absl::StatusOr<SessionState> MemorySessionStore::Put(SessionState state,
                                                     uint64_t expected_version) {
  return Replace(std::move(state), expected_version, /*same_version=*/false);
}

absl::StatusOr<SessionState> MemorySessionStore::PutSameVersion(SessionState state,
                                                                uint64_t expected_version) {
  return Replace(std::move(state), expected_version, /*same_version=*/true);
}

absl::StatusOr<SessionState> MemorySessionStore::Replace(SessionState state,
                                                         uint64_t expected_version,
                                                         bool same_version) {
  std::lock_guard lock(mutex_);
  auto it = by_id_.find(state.session.id());
  if (it == by_id_.end()) return NotFound(state.session.id());
  const inbetween::v1::Session& current = it->second.state.session;
  if (auto s = CheckPutVersion(current.id(), current.version(), expected_version); !s.ok()) {
    return s;
  }
  StampPut(state, current, same_version);
  it->second.state = std::move(state);
  return it->second.state;
}

absl::StatusOr<SessionPage> MemorySessionStore::List(size_t page_size, absl::string_view page_token,
                                                     absl::string_view owner) const {
  absl::StatusOr<uint64_t> after = ParsePageToken(page_token);
  if (!after.ok()) return after.status();
  std::lock_guard lock(mutex_);
  return PageBySequence(by_sequence_, page_size, *after,
                        [&](const std::string& id, SessionState* out) {
                          const SessionState& state = by_id_.find(id)->second.state;
                          if (state.owner != owner) return false;
                          *out = state;
                          return true;
                        });
}

size_t MemorySessionStore::CountOwned(absl::string_view owner) const {
  std::lock_guard lock(mutex_);
  size_t n = 0;
  for (const auto& [id, entry] : by_id_) n += entry.state.owner == owner;
  return n;
}

size_t MemorySessionStore::Count() const {
  std::lock_guard lock(mutex_);
  return by_id_.size();
}

absl::Status MemorySessionStore::Delete(absl::string_view id, uint64_t expected_version) {
  std::lock_guard lock(mutex_);
  auto it = by_id_.find(id);
  if (it == by_id_.end()) return NotFound(id);
  const uint64_t version = it->second.state.session.version();
  if (auto s = CheckDeleteVersion(id, version, expected_version); !s.ok()) return s;
  by_sequence_.erase(it->second.sequence);
  by_id_.erase(it);
  return absl::OkStatus();
}

}  // namespace inbetween::server
