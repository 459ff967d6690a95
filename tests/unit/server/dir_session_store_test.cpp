// DirSessionStore: versions on disk, reopening finds every session with its multimesh, listing
// by owner, deletion, old snapshots trimmed.
#include "server/dir_session_store.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

namespace fs = std::filesystem;

class DirSessionStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("dir_store_test_" + std::to_string(getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  std::unique_ptr<DirSessionStore> Open() {
    auto store = DirSessionStore::Open(root_.string());
    EXPECT_TRUE(store.ok()) << store.status();
    return store.ok() ? *std::move(store) : nullptr;
  }

  fs::path root_;
};

TEST_F(DirSessionStoreTest, SessionsSurviveReopeningWithTheirMultimesh) {
  std::string id;
  {
    auto store = Open();
    auto created = store->Create(StoredSessionState("alice"));
    ASSERT_TRUE(created.ok()) << created.status();
    id = created->session.id();
    for (uint64_t v = 1; v <= 4; ++v) {
      SessionState next = *created;
      next.session.set_display_name("v" + std::to_string(v + 1));
      auto put = store->Put(next, v);
      ASSERT_TRUE(put.ok()) << put.status();
      EXPECT_EQ(put->session.version(), v + 1);
    }
    EXPECT_EQ(store->Put(*created, 1).status().code(), absl::StatusCode::kAborted);
    ASSERT_TRUE(store->Create(StoredSessionState("bob")).ok());
  }
  // Only the newest snapshots are kept.
  int files = 0;
  for (const auto& f : fs::directory_iterator(root_ / "sessions" / id))
    files += f.is_regular_file();
  EXPECT_EQ(files, 2);

  auto store = Open();
  EXPECT_EQ(store->Count(), 2u);
  EXPECT_EQ(store->CountOwned("alice"), 1u);
  auto got = store->Get(id);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->session.version(), 5u);
  EXPECT_EQ(got->session.display_name(), "v5");
  EXPECT_EQ(got->owner, "alice");
  EXPECT_EQ(got->next_drawing_id, 2u);
  ASSERT_EQ(got->parsed.size(), 1u);
  EXPECT_EQ(got->parsed[0].outlines.size(), 1u);
  ASSERT_TRUE(got->multimesh);
  EXPECT_EQ(got->multimesh->triangles.size(), 2u);
  EXPECT_EQ(got->multimesh->shapes[1][2], solver::Point(2, 2));
  EXPECT_EQ(got->multimesh->boundary_loops.size(), 1u);

  auto page = store->List(10, "", "alice");
  ASSERT_TRUE(page.ok());
  ASSERT_EQ(page->sessions.size(), 1u);
  EXPECT_EQ(page->sessions[0].session.id(), id);

  // Versions go on after a restart; a deletion is durable.
  ASSERT_TRUE(store->Put(*got, 5).ok());
  ASSERT_TRUE(store->Delete(id, 6).ok());
  EXPECT_EQ(store->Get(id).status().code(), absl::StatusCode::kNotFound);
  store.reset();
  store = Open();
  EXPECT_EQ(store->Get(id).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store->Count(), 1u);
}

TEST_F(DirSessionStoreTest, LeftoverTempFilesAreIgnored) {
  std::string id;
  {
    auto store = Open();
    auto created = store->Create(StoredSessionState(""));
    ASSERT_TRUE(created.ok());
    id = created->session.id();
  }
  // A crash between write and rename leaves a temp file behind; it is not a version.
  std::FILE* f = std::fopen((root_ / "sessions" / id / ".tmp-junk").c_str(), "w");
  std::fputs("partial", f);
  std::fclose(f);
  auto store = Open();
  auto got = store->Get(id);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->session.version(), 1u);
  EXPECT_FALSE(fs::exists(root_ / "sessions" / id / ".tmp-junk"));
}

TEST_F(DirSessionStoreTest, IdleSessionsLeaveMemoryAndReload) {
  auto store = Open();
  auto created = store->Create(StoredSessionState("alice"));
  ASSERT_TRUE(created.ok()) << created.status();
  EXPECT_EQ(store->CachedCount(), 1u);
  // Used just now: not idle before a point in the past.
  EXPECT_EQ(store->EvictIdle(std::chrono::steady_clock::now() - std::chrono::hours(1)), 0u);
  EXPECT_EQ(store->CachedCount(), 1u);
  EXPECT_EQ(store->EvictIdle(std::chrono::steady_clock::now() + std::chrono::seconds(1)), 1u);
  EXPECT_EQ(store->CachedCount(), 0u);
  auto got = store->Get(created->session.id());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(store->CachedCount(), 1u);
  EXPECT_EQ(got->session.version(), 1u);
  ASSERT_TRUE(got->multimesh);
  EXPECT_EQ(got->multimesh->triangles.size(), 2u);
}

TEST_F(DirSessionStoreTest, PutSameVersionKeepsTheVersionAndSurvivesReopening) {
  std::string id;
  {
    auto store = Open();
    auto created = store->Create(StoredSessionState("alice"));
    ASSERT_TRUE(created.ok()) << created.status();
    id = created->session.id();
    SessionState next = *created;
    auto checkpoint = std::make_shared<StoredComeshCheckpoint>();
    checkpoint->input_version = checkpoint->stored_version = 1;
    checkpoint->checkpoint.mesh = *created->multimesh;
    checkpoint->checkpoint.outer = 3;
    next.comesh_checkpoint = checkpoint;
    EXPECT_EQ(store->PutSameVersion(next, 2).status().code(), absl::StatusCode::kAborted);
    auto put = store->PutSameVersion(next, 1);
    ASSERT_TRUE(put.ok()) << put.status();
    EXPECT_EQ(put->session.version(), 1u);
  }
  auto store = Open();
  auto got = store->Get(id);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->session.version(), 1u);
  ASSERT_NE(got->comesh_checkpoint, nullptr);
  EXPECT_EQ(got->comesh_checkpoint->checkpoint.outer, 3);
  // The next ordinary write goes on from the same version.
  auto put = store->Put(*got, 1);
  ASSERT_TRUE(put.ok()) << put.status();
  EXPECT_EQ(put->session.version(), 2u);
}

}  // namespace
}  // namespace inbetween::server::testing
