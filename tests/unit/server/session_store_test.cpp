// MemorySessionStore: ids, optimistic locking, deterministic paging, delete semantics.
#include "server/session_store.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <string>

namespace inbetween::server {
namespace {

using ::testing::HasSubstr;

SessionState Named(const std::string& name) {
  SessionState state;
  state.session.set_display_name(name);
  return state;
}

TEST(MemorySessionStoreTest, CreateAssignsUrlSafeUniqueIdsAndVersionOne) {
  MemorySessionStore store;
  std::set<std::string> ids;
  for (int i = 0; i < 100; ++i) {
    absl::StatusOr<SessionState> state = store.Create(Named("s"));
    ASSERT_TRUE(state.ok()) << state.status();
    const std::string& id = state->session.id();
    EXPECT_EQ(id.size(), 16u);
    EXPECT_EQ(id.find_first_not_of("0123456789abcdef"), std::string::npos) << id;
    EXPECT_EQ(state->session.version(), 1u);
    EXPECT_GT(state->session.created_unix_ms(), 0);
    ids.insert(id);
  }
  EXPECT_EQ(ids.size(), 100u);
}

TEST(MemorySessionStoreTest, CreateWithTakenIdIsAlreadyExists) {
  MemorySessionStore store;
  SessionState state = Named("a");
  state.session.set_id("fixed");
  ASSERT_TRUE(store.Create(state).ok());
  EXPECT_EQ(store.Create(state).status().code(), absl::StatusCode::kAlreadyExists);
}

TEST(MemorySessionStoreTest, PutIncrementsVersionAndRejectsStaleVersion) {
  MemorySessionStore store;
  SessionState state = *store.Create(Named("a"));
  const std::string id = state.session.id();
  state.session.set_display_name("b");
  absl::StatusOr<SessionState> put = store.Put(state, 1);
  ASSERT_TRUE(put.ok()) << put.status();
  EXPECT_EQ(put->session.version(), 2u);
  EXPECT_EQ(store.Get(id)->session.display_name(), "b");

  absl::Status stale = store.Put(state, 1).status();
  EXPECT_EQ(stale.code(), absl::StatusCode::kAborted);
  EXPECT_EQ(stale.message(), "session " + id + " is at version 2, request expected 1");
}

TEST(MemorySessionStoreTest, UnknownIdIsNotFound) {
  MemorySessionStore store;
  EXPECT_EQ(store.Get("nope").status().code(), absl::StatusCode::kNotFound);
  SessionState state = Named("x");
  state.session.set_id("nope");
  EXPECT_EQ(store.Put(state, 1).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store.Delete("nope", 0).code(), absl::StatusCode::kNotFound);
}

TEST(MemorySessionStoreTest, DeleteChecksVersionUnlessZero) {
  MemorySessionStore store;
  const std::string a = store.Create(Named("a"))->session.id();
  const std::string b = store.Create(Named("b"))->session.id();
  EXPECT_EQ(store.Delete(a, 5).code(), absl::StatusCode::kAborted);
  EXPECT_TRUE(store.Delete(a, 1).ok());
  EXPECT_TRUE(store.Delete(b, 0).ok());
  EXPECT_EQ(store.Get(a).status().code(), absl::StatusCode::kNotFound);
}

TEST(MemorySessionStoreTest, ListPagesInCreationOrder) {
  MemorySessionStore store;
  std::vector<std::string> created;
  for (int i = 0; i < 7; ++i) created.push_back(store.Create(Named("s"))->session.id());
  std::vector<std::string> listed;
  std::string token;
  int pages = 0;
  do {
    absl::StatusOr<SessionPage> page = store.List(3, token, "");
    ASSERT_TRUE(page.ok()) << page.status();
    for (const SessionState& s : page->sessions) listed.push_back(s.session.id());
    token = page->next_page_token;
    ++pages;
  } while (!token.empty());
  EXPECT_EQ(listed, created);
  EXPECT_EQ(pages, 3);

  // A deletion between pages neither repeats nor skips the remaining sessions.
  absl::StatusOr<SessionPage> first = store.List(3, "", "");
  ASSERT_TRUE(store.Delete(created[3], 0).ok());
  absl::StatusOr<SessionPage> second = store.List(3, first->next_page_token, "");
  ASSERT_EQ(second->sessions.size(), 3u);
  EXPECT_EQ(second->sessions[0].session.id(), created[4]);
  EXPECT_TRUE(second->next_page_token.empty());
}

TEST(MemorySessionStoreTest, BadPageTokenIsInvalidArgument) {
  MemorySessionStore store;
  absl::Status status = store.List(10, "garbage", "").status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("page_token"));
}

TEST(MemorySessionStoreTest, SessionLimitIsResourceExhausted) {
  MemorySessionStore store(2);
  ASSERT_TRUE(store.Create(Named("a")).ok());
  ASSERT_TRUE(store.Create(Named("b")).ok());
  EXPECT_EQ(store.Create(Named("c")).status().code(), absl::StatusCode::kResourceExhausted);
}

}  // namespace
}  // namespace inbetween::server
