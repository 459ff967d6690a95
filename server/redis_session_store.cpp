// RedisSessionStore over hiredis's synchronous API: a small pool of connections (one per
// concurrent call), Lua scripts for every check-and-write, a per-process cache validated by the
// version stored in Redis.
#include "server/redis_session_store.h"

#include <hiredis/hiredis.h>
#include <spdlog/spdlog.h>

#include <charconv>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "server/session_snapshot.h"
#include "solver/core/error_reason.h"

namespace inbetween::server {

class RedisSessionStore::Reply {
 public:
  explicit Reply(redisReply* reply) : reply_(reply, &freeReplyObject) {}
  const redisReply& operator*() const { return *reply_; }
  const redisReply* operator->() const { return reply_.get(); }
  bool null() const { return reply_ == nullptr; }

 private:
  std::unique_ptr<redisReply, void (*)(void*)> reply_;
};

namespace {

constexpr absl::string_view kPrefix = "inbetween:";

std::string SessionKey(absl::string_view id) { return absl::StrCat(kPrefix, "s:", id); }
std::string AllKey() { return absl::StrCat(kPrefix, "all"); }
std::string OwnerKey(absl::string_view owner) { return absl::StrCat(kPrefix, "own:", owner); }
std::string SequenceKey() { return absl::StrCat(kPrefix, "seq"); }

// Lua shared by the scripts below: `now` (Redis' clock, ms) and `sweep`, which drops the index
// entries (all, own:<owner>, owner, exp) of up to 256 sessions whose hash has expired. An entry of
// exp is a lower bound (a read extends the TTL without touching exp): a session still present is
// re-scored by its real expiry. The ZADD is a pcall so that a sweep never fails for memory.
static_assert(kPrefix == "inbetween:", "kSweepLua's P must equal kPrefix");
constexpr char kSweepLua[] = R"lua(
local P = 'inbetween:'
local function now()
  local t = redis.call('TIME')
  return tonumber(t[1]) * 1000 + math.floor(tonumber(t[2]) / 1000)
end
local function sweep()
  local due = redis.call('ZRANGEBYSCORE', P .. 'exp', '-inf', now(), 'LIMIT', 0, 256)
  for _, id in ipairs(due) do
    local at = redis.call('PEXPIRETIME', P .. 's:' .. id)
    if at == -2 then
      local o = redis.call('HGET', P .. 'owner', id)
      redis.call('ZREM', P .. 'all', id)
      if o then redis.call('ZREM', P .. 'own:' .. o, id) end
      redis.call('HDEL', P .. 'owner', id)
      redis.call('ZREM', P .. 'exp', id)
    elseif at == -1 then
      redis.call('ZREM', P .. 'exp', id)
    else
      redis.pcall('ZADD', P .. 'exp', at, id)
    end
  end
end
-- Sets the session's expiry ttl ms from now (0: none) and records it in exp.
local function retain(key, id, ttl)
  if ttl > 0 then
    redis.call('PEXPIRE', key, ttl)
    redis.call('ZADD', P .. 'exp', now() + ttl, id)
  else
    redis.call('PERSIST', key)
    redis.call('ZREM', P .. 'exp', id)
  end
end
)lua";

// KEYS: session, all, own:<owner>, seq. ARGV: id, max sessions, version, owner, created,
// summary, snapshot, ttl ms. Returns {"ok", sequence} | {"exists"} | {"full"}.
constexpr char kCreateBody[] = R"lua(
sweep()
if redis.call('EXISTS', KEYS[1]) == 1 then return {'exists'} end
if redis.call('ZCARD', KEYS[2]) >= tonumber(ARGV[2]) then return {'full'} end
local q = redis.call('INCR', KEYS[4])
redis.call('HSET', KEYS[1], 'v', ARGV[3], 'o', ARGV[4], 'c', ARGV[5], 'q', q, 'm', ARGV[6],
           'd', ARGV[7])
redis.call('ZADD', KEYS[2], q, ARGV[1])
redis.call('ZADD', KEYS[3], q, ARGV[1])
redis.call('HSET', P .. 'owner', ARGV[1], ARGV[4])
retain(KEYS[1], ARGV[1], tonumber(ARGV[8]))
return {'ok', tostring(q)}
)lua";

// KEYS: session. ARGV: expected version, new version, summary, snapshot, id, ttl ms.
// Returns {"ok"} | {"missing"} | {"stale", current version}.
constexpr char kPutBody[] = R"lua(
local v = redis.call('HGET', KEYS[1], 'v')
if not v then return {'missing'} end
if v ~= ARGV[1] then return {'stale', v} end
redis.call('HSET', KEYS[1], 'v', ARGV[2], 'm', ARGV[3], 'd', ARGV[4])
retain(KEYS[1], ARGV[5], tonumber(ARGV[6]))
return {'ok'}
)lua";

// KEYS: session. ARGV: ttl ms. The version, and a read counts as use: the TTL starts again.
// PEXPIRE and PERSIST are allowed when Redis is out of memory, so reads keep working then.
constexpr char kTouchScript[] = R"lua(
local v = redis.call('HGET', KEYS[1], 'v')
if v then
  if tonumber(ARGV[1]) > 0 then redis.call('PEXPIRE', KEYS[1], ARGV[1])
  else redis.call('PERSIST', KEYS[1]) end
end
return v
)lua";

// KEYS: session, all, own:<owner>. ARGV: expected version (0 = any), id.
// Returns {"ok"} | {"missing"} | {"stale", current version}.
constexpr char kDeleteBody[] = R"lua(
local v = redis.call('HGET', KEYS[1], 'v')
if not v then return {'missing'} end
if ARGV[1] ~= '0' and v ~= ARGV[1] then return {'stale', v} end
redis.call('DEL', KEYS[1])
redis.call('ZREM', KEYS[2], ARGV[2])
redis.call('ZREM', KEYS[3], ARGV[2])
redis.call('HDEL', P .. 'owner', ARGV[2])
redis.call('ZREM', P .. 'exp', ARGV[2])
return {'ok'}
)lua";

// KEYS: a sorted set (all or own:<owner>). Its size once expired sessions are swept.
constexpr char kCountBody[] = R"lua(
sweep()
return redis.call('ZCARD', KEYS[1])
)lua";

const std::string& Script(const char* body) {
  static const auto* scripts = new std::map<const char*, std::string>{
      {kCreateBody, absl::StrCat(kSweepLua, kCreateBody)},
      {kPutBody, absl::StrCat(kSweepLua, kPutBody)},
      {kDeleteBody, absl::StrCat(kSweepLua, kDeleteBody)},
      {kCountBody, absl::StrCat(kSweepLua, kCountBody)},
  };
  return scripts->at(body);
}

// KEYS: own:<owner>. ARGV: after sequence, count, session key prefix.
// Returns id, sequence, summary triples (one consistent view of the index and the summaries).
constexpr char kListScript[] = R"lua(
local r = redis.call('ZRANGEBYSCORE', KEYS[1], '(' .. ARGV[1], '+inf', 'WITHSCORES', 'LIMIT', 0,
                     tonumber(ARGV[2]))
local out = {}
for i = 1, #r, 2 do
  local m = redis.call('HGET', ARGV[3] .. r[i], 'm')
  if m then
    table.insert(out, r[i])
    table.insert(out, r[i + 1])
    table.insert(out, m)
  end
end
return out
)lua";

absl::string_view Str(const redisReply& reply) { return absl::string_view(reply.str, reply.len); }

// The first element of a script's array reply ("ok", "stale", ...), or "" when malformed.
absl::string_view Verdict(const redisReply& reply) {
  if (reply.type != REDIS_REPLY_ARRAY || reply.elements == 0 ||
      reply.element[0]->type != REDIS_REPLY_STRING) {
    return "";
  }
  return Str(*reply.element[0]);
}

uint64_t ElementU64(const redisReply& reply, size_t i) {
  uint64_t v = 0;
  if (reply.type == REDIS_REPLY_ARRAY && i < reply.elements &&
      reply.element[i]->type == REDIS_REPLY_STRING) {
    (void)absl::SimpleAtoi(Str(*reply.element[i]), &v);
  }
  return v;
}

absl::Status Malformed(absl::string_view what) {
  return absl::InternalError(absl::StrCat("session store: unexpected Redis reply to ", what));
}

// Where a redis:// URL's credentials end ('@' before the host), or npos.
size_t CredentialsEnd(absl::string_view url) {
  absl::string_view rest = url;
  if (!absl::ConsumePrefix(&rest, "redis://")) return absl::string_view::npos;
  const size_t at = rest.substr(0, rest.find('/')).rfind('@');
  return at == absl::string_view::npos ? at : at + 8;
}

}  // namespace

std::string RedactRedisUrl(absl::string_view url) {
  const size_t at = CredentialsEnd(url);
  if (at == absl::string_view::npos) return std::string(url);
  return absl::StrCat("redis://***", url.substr(at));
}

absl::StatusOr<RedisAddress> ParseRedisUrl(absl::string_view url) {
  const auto bad = [&](absl::string_view why) {
    return absl::InvalidArgumentError(absl::StrCat("--store: '", RedactRedisUrl(url), "' ", why,
                                                   " (use redis://[[USER]:PASSWORD@]HOST:PORT[/DB])"));
  };
  absl::string_view rest = url;
  if (!absl::ConsumePrefix(&rest, "redis://")) return bad("is not a redis:// URL");
  RedisAddress address;
  if (const size_t at = CredentialsEnd(url); at != absl::string_view::npos) {
    const absl::string_view credentials = url.substr(8, at - 8);
    const size_t colon = credentials.find(':');
    if (colon == absl::string_view::npos) return bad("has credentials without ':PASSWORD'");
    address.user = std::string(credentials.substr(0, colon));
    address.password = std::string(credentials.substr(colon + 1));
    rest = url.substr(at + 1);
  }
  if (const size_t slash = rest.find('/'); slash != absl::string_view::npos) {
    if (!absl::SimpleAtoi(rest.substr(slash + 1), &address.db) || address.db < 0) {
      return bad("has a database that is not a number");
    }
    rest = rest.substr(0, slash);
  }
  const size_t colon = rest.rfind(':');
  if (colon == absl::string_view::npos || colon == 0) return bad("needs HOST:PORT");
  absl::string_view host = rest.substr(0, colon);
  if (absl::ConsumePrefix(&host, "[") && !absl::ConsumeSuffix(&host, "]")) {
    return bad("has an unclosed [IPv6] host");
  }
  if (host.empty()) return bad("needs a host");
  if (!absl::SimpleAtoi(rest.substr(colon + 1), &address.port) || address.port <= 0 ||
      address.port > 65535) {
    return bad("has a port that is not 1..65535");
  }
  address.host = std::string(host);
  return address;
}

RedisSessionStore::RedisSessionStore(RedisAddress address, RedisStoreOptions options)
    : address_(std::move(address)), options_(std::move(options)), rng_(std::random_device{}()) {}

std::string RedisSessionStore::Where() const {
  return absl::StrCat("session store: redis ", address_.host, ":", address_.port);
}

RedisSessionStore::~RedisSessionStore() {
  for (redisContext* c : idle_) redisFree(c);
}

absl::StatusOr<std::unique_ptr<RedisSessionStore>> RedisSessionStore::Open(
    absl::string_view url, RedisStoreOptions options) {
  absl::StatusOr<RedisAddress> address = ParseRedisUrl(url);
  if (!address.ok()) return address.status();
  if (!options.password.empty()) {
    address->user.clear();  // --redis-password-file: the default user
    address->password = options.password;
  }
  std::unique_ptr<RedisSessionStore> store(new RedisSessionStore(*address, std::move(options)));
  absl::StatusOr<Reply> pong = store->Command({"PING"});
  if (!pong.ok()) {
    return absl::UnavailableError(
        absl::StrCat("--store ", RedactRedisUrl(url), ": ", pong.status().message()));
  }
  return store;
}

absl::StatusOr<redisContext*> RedisSessionStore::Connect() const {
  const auto ms = options_.timeout.count();
  const timeval timeout{static_cast<time_t>(ms / 1000), static_cast<suseconds_t>(ms % 1000 * 1000)};
  redisContext* c = redisConnectWithTimeout(address_.host.c_str(), address_.port, timeout);
  const std::string where = Where();
  if (c == nullptr) return absl::UnavailableError(absl::StrCat(where, ": out of memory"));
  if (c->err != 0) {
    absl::Status error = absl::UnavailableError(absl::StrCat(where, ": ", c->errstr));
    redisFree(c);
    return error;
  }
  redisSetTimeout(c, timeout);
  if (!address_.password.empty()) {
    std::vector<const char*> argv = {"AUTH"};
    std::vector<size_t> lengths = {4};
    if (!address_.user.empty()) {
      argv.push_back(address_.user.data());
      lengths.push_back(address_.user.size());
    }
    argv.push_back(address_.password.data());
    lengths.push_back(address_.password.size());
    Reply reply(static_cast<redisReply*>(
        redisCommandArgv(c, static_cast<int>(argv.size()), argv.data(), lengths.data())));
    if (reply.null() || reply->type == REDIS_REPLY_ERROR) {
      absl::Status error = absl::UnavailableError(absl::StrCat(
          where, ": AUTH refused: ", reply.null() ? absl::string_view(c->errstr) : Str(*reply)));
      redisFree(c);
      return error;
    }
  }
  if (address_.db != 0) {
    Reply reply(static_cast<redisReply*>(redisCommand(c, "SELECT %d", address_.db)));
    if (reply.null() || reply->type == REDIS_REPLY_ERROR) {
      redisFree(c);
      return absl::UnavailableError(absl::StrCat(where, ": cannot select database ", address_.db));
    }
  }
  return c;
}

absl::StatusOr<RedisSessionStore::Reply> RedisSessionStore::Command(
    const std::vector<std::string>& args, bool idempotent) const {
  std::vector<const char*> argv;
  std::vector<size_t> lengths;
  for (const std::string& a : args) {
    argv.push_back(a.data());
    lengths.push_back(a.size());
  }
  for (int attempt = 0;; ++attempt) {
    redisContext* c = nullptr;
    {
      std::lock_guard lock(pool_mutex_);
      if (!idle_.empty()) {
        c = idle_.back();
        idle_.pop_back();
      }
    }
    const bool pooled = c != nullptr;
    if (!pooled) {
      absl::StatusOr<redisContext*> fresh = Connect();
      if (!fresh.ok()) return fresh.status();
      c = *fresh;
    }
    Reply reply(static_cast<redisReply*>(
        redisCommandArgv(c, static_cast<int>(args.size()), argv.data(), lengths.data())));
    if (reply.null()) {
      // The connection is broken (Redis restarted, or a timeout mid-reply): never reuse it, nor
      // the other idle ones (they most likely broke the same way). A read that failed on a
      // pooled connection is tried once more on a fresh one; a write is not (it may have run).
      absl::Status error = absl::UnavailableError(absl::StrCat(Where(), ": ", c->errstr));
      redisFree(c);
      std::vector<redisContext*> stale;
      {
        std::lock_guard lock(pool_mutex_);
        stale.swap(idle_);
      }
      for (redisContext* s : stale) redisFree(s);
      if (pooled && idempotent && attempt == 0) continue;
      return error;
    }
    {
      std::lock_guard lock(pool_mutex_);
      idle_.push_back(c);
    }
    if (reply->type == REDIS_REPLY_ERROR) {
      const absl::string_view text = Str(*reply);
      if (absl::StrContains(text, "OOM command not allowed")) {
        // maxmemory reached under noeviction: nothing was written (the scripts' first growing
        // command is refused before any change).
        return solver::WithReason(
            absl::ResourceExhaustedError(absl::StrCat(
                Where(), " is out of memory (maxmemory): no new session or change can be stored "
                         "until sessions expire or are deleted; reads still work")),
            solver::kReasonStoreFull);
      }
      if (absl::StartsWith(text, "NOAUTH")) {
        return absl::UnavailableError(absl::StrCat(
            Where(), " needs a password: ", text,
            " (give it with --redis-password-file or in the --store URL)"));
      }
      return absl::InternalError(absl::StrCat(Where(), " ", args[0], ": ", text));
    }
    return reply;
  }
}

void RedisSessionStore::Remember(const SessionState& state) const {
  std::lock_guard lock(cache_mutex_);
  Cached& entry = cache_[state.session.id()];
  entry.state = state;
  entry.last_used = ++clock_;
  entry.used_at = std::chrono::steady_clock::now();
  while (cache_.size() > std::max<size_t>(1, options_.max_cached)) {
    auto oldest = cache_.begin();
    for (auto it = cache_.begin(); it != cache_.end(); ++it) {
      if (it->second.last_used < oldest->second.last_used) oldest = it;
    }
    cache_.erase(oldest);
  }
}

absl::StatusOr<SessionState> RedisSessionStore::Get(absl::string_view id) const {
  return Load(id, /*use_cache=*/true);
}

// The cache is valid while the version in Redis is unchanged, which PutSameVersion on another
// replica does not change: this reads the snapshot whatever the cache holds.
absl::StatusOr<SessionState> RedisSessionStore::GetLatest(absl::string_view id) const {
  return Load(id, /*use_cache=*/false);
}

absl::StatusOr<SessionState> RedisSessionStore::Load(absl::string_view id, bool use_cache) const {
  const std::string key = SessionKey(id);
  absl::StatusOr<Reply> version = Command({"EVAL", kTouchScript, "1", key, TtlArgument()});
  if (!version.ok()) return version.status();
  if ((*version)->type == REDIS_REPLY_NIL) {
    std::lock_guard lock(cache_mutex_);
    if (auto it = cache_.find(id); it != cache_.end()) cache_.erase(it);
    return SessionNotFoundError(id);
  }
  uint64_t current = 0;
  if ((*version)->type != REDIS_REPLY_STRING || !absl::SimpleAtoi(Str(**version), &current)) {
    return Malformed("HGET v");
  }
  if (use_cache) {
    std::lock_guard lock(cache_mutex_);
    if (auto it = cache_.find(id);
        it != cache_.end() && it->second.state.session.version() == current) {
      it->second.last_used = ++clock_;
      it->second.used_at = std::chrono::steady_clock::now();
      return it->second.state;
    }
  }
  // Not cached here, or another replica wrote a newer version: load the snapshot.
  absl::StatusOr<Reply> bytes = Command({"HGET", key, "d"});
  if (!bytes.ok()) return bytes.status();
  if ((*bytes)->type == REDIS_REPLY_NIL) return SessionNotFoundError(id);  // deleted meanwhile
  if ((*bytes)->type != REDIS_REPLY_STRING) return Malformed("HGET d");
  absl::StatusOr<SessionState> state = DecodeSnapshot(Str(**bytes), key);
  if (!state.ok()) return state.status();
  Remember(*state);
  return state;
}

absl::StatusOr<SessionState> RedisSessionStore::Create(SessionState state) {
  const bool chosen_id = !state.session.id().empty();
  for (int attempt = 0; attempt < 8; ++attempt) {
    std::string id = state.session.id();
    if (!chosen_id) {
      std::lock_guard lock(rng_mutex_);
      id = RandomSessionId(rng_);
    }
    SessionState stamped = state;
    StampCreated(stamped, id);
    absl::StatusOr<Reply> reply =
        Command({"EVAL", Script(kCreateBody), "4", SessionKey(id), AllKey(),
                 OwnerKey(stamped.owner), SequenceKey(), id, absl::StrCat(options_.max_sessions),
                 absl::StrCat(stamped.session.version()), stamped.owner,
                 absl::StrCat(stamped.session.created_unix_ms()),
                 SessionSummary(stamped.session).SerializeAsString(), EncodeSnapshot(stamped),
                 TtlArgument()},
                /*idempotent=*/false);
    if (!reply.ok()) return reply.status();
    const absl::string_view verdict = Verdict(**reply);
    if (verdict == "ok") {
      Remember(stamped);
      return stamped;
    }
    if (verdict == "full") {
      return SessionLimitError(options_.max_sessions);
    }
    if (verdict != "exists") return Malformed("create");
    if (chosen_id) return absl::AlreadyExistsError(absl::StrCat("session ", id, " already exists"));
  }
  return absl::InternalError("session store: no free session id after 8 attempts");
}

absl::StatusOr<SessionState> RedisSessionStore::Put(SessionState state, uint64_t expected_version) {
  return Replace(std::move(state), expected_version, /*same_version=*/false);
}

absl::StatusOr<SessionState> RedisSessionStore::PutSameVersion(SessionState state,
                                                               uint64_t expected_version) {
  return Replace(std::move(state), expected_version, /*same_version=*/true);
}

absl::StatusOr<SessionState> RedisSessionStore::Replace(SessionState state,
                                                        uint64_t expected_version,
                                                        bool same_version) {
  const std::string id = state.session.id();
  const std::string key = SessionKey(id);
  // Owner and created time never change after Create, so reading them outside the script is
  // safe; the version check happens inside it.
  absl::StatusOr<Reply> fixed = Command({"HMGET", key, "o", "c"});
  if (!fixed.ok()) return fixed.status();
  if ((*fixed)->type != REDIS_REPLY_ARRAY || (*fixed)->elements != 2) return Malformed("HMGET");
  if ((*fixed)->element[0]->type != REDIS_REPLY_STRING) return SessionNotFoundError(id);
  inbetween::v1::Session current;
  current.set_version(expected_version);
  current.set_created_unix_ms(static_cast<int64_t>(ElementU64(**fixed, 1)));
  StampPut(state, current, same_version);
  state.owner = std::string(Str(*(*fixed)->element[0]));
  absl::StatusOr<Reply> reply =
      Command({"EVAL", Script(kPutBody), "1", key, absl::StrCat(expected_version),
               absl::StrCat(state.session.version()),
               SessionSummary(state.session).SerializeAsString(), EncodeSnapshot(state), id,
               TtlArgument()},
              /*idempotent=*/false);
  if (!reply.ok()) return reply.status();
  const absl::string_view verdict = Verdict(**reply);
  if (verdict == "missing") return SessionNotFoundError(id);
  if (verdict == "stale") return StaleVersionError(id, ElementU64(**reply, 1), expected_version);
  if (verdict != "ok") return Malformed("put");
  Remember(state);
  return state;
}

absl::StatusOr<SessionPage> RedisSessionStore::List(size_t page_size, absl::string_view page_token,
                                                    absl::string_view owner) const {
  absl::StatusOr<uint64_t> after = ParsePageToken(page_token);
  if (!after.ok()) return after.status();
  // One more than the page, so PageBySequence knows whether another page follows.
  absl::StatusOr<Reply> reply =
      Command({"EVAL", kListScript, "1", OwnerKey(owner), absl::StrCat(*after),
               absl::StrCat(page_size + 1), absl::StrCat(kPrefix, "s:")});
  if (!reply.ok()) return reply.status();
  const redisReply& r = **reply;
  if (r.type != REDIS_REPLY_ARRAY || r.elements % 3 != 0) return Malformed("list");
  std::map<uint64_t, std::string> by_sequence;
  std::map<std::string, inbetween::v1::Session, std::less<>> summaries;
  for (size_t i = 0; i < r.elements; i += 3) {
    const std::string id(Str(*r.element[i]));
    inbetween::v1::Session summary;
    const absl::string_view bytes = Str(*r.element[i + 2]);
    if (!summary.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) {
      return Malformed("list (summary)");
    }
    by_sequence.emplace(ElementU64(r, i + 1), id);
    summaries.emplace(id, std::move(summary));
  }
  return PageBySequence(by_sequence, page_size, *after,
                        [&](const std::string& id, SessionState* state) {
                          state->session = summaries.at(id);
                          state->owner = std::string(owner);
                          return true;
                        });
}

size_t RedisSessionStore::CountOwned(absl::string_view owner) const {
  absl::StatusOr<Reply> reply = Command({"EVAL", Script(kCountBody), "1", OwnerKey(owner)});
  if (!reply.ok() || (*reply)->type != REDIS_REPLY_INTEGER) {
    spdlog::warn("session store: cannot count sessions: {}",
                 reply.ok() ? "bad reply" : std::string(reply.status().message()));
    return 0;
  }
  return static_cast<size_t>((*reply)->integer);
}

size_t RedisSessionStore::Count() const {
  absl::StatusOr<Reply> reply = Command({"EVAL", Script(kCountBody), "1", AllKey()});
  if (!reply.ok() || (*reply)->type != REDIS_REPLY_INTEGER) return 0;
  return static_cast<size_t>((*reply)->integer);
}

absl::Status RedisSessionStore::Delete(absl::string_view id, uint64_t expected_version) {
  const std::string key = SessionKey(id);
  absl::StatusOr<Reply> owner = Command({"HGET", key, "o"});
  if (!owner.ok()) return owner.status();
  if ((*owner)->type != REDIS_REPLY_STRING) return SessionNotFoundError(id);
  absl::StatusOr<Reply> reply =
      Command({"EVAL", Script(kDeleteBody), "3", key, AllKey(), OwnerKey(Str(**owner)),
               absl::StrCat(expected_version), std::string(id)},
              /*idempotent=*/false);
  if (!reply.ok()) return reply.status();
  const absl::string_view verdict = Verdict(**reply);
  if (verdict == "missing") return SessionNotFoundError(id);
  if (verdict == "stale") return StaleVersionError(id, ElementU64(**reply, 1), expected_version);
  if (verdict != "ok") return Malformed("delete");
  std::lock_guard lock(cache_mutex_);
  if (auto it = cache_.find(id); it != cache_.end()) cache_.erase(it);
  return absl::OkStatus();
}

size_t RedisSessionStore::EvictIdle(std::chrono::steady_clock::time_point idle_before) {
  std::lock_guard lock(cache_mutex_);
  return std::erase_if(cache_,
                       [&](const auto& entry) { return entry.second.used_at < idle_before; });
}

size_t RedisSessionStore::CachedCount() const {
  std::lock_guard lock(cache_mutex_);
  return cache_.size();
}

}  // namespace inbetween::server
