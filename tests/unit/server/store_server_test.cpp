// InbetweenServer with persistent stores: idle sessions leave memory (--idle-evict-seconds) and
// reload on the next call; two servers over one Redis act as replicas through real RPCs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "tests/unit/server/redis_fixture.h"
#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

namespace fs = std::filesystem;

std::unique_ptr<InbetweenServer> StartWithStore(const std::string& store,
                                                std::chrono::seconds idle_evict) {
  ServerOptions options;
  options.store = store;
  options.idle_evict = idle_evict;
  options.shutdown_grace = std::chrono::milliseconds(200);
  auto server = InbetweenServer::Start(options);
  EXPECT_TRUE(server.ok()) << server.status();
  return server.ok() ? *std::move(server) : nullptr;
}

v1::Session Create(v1::Inbetween::Stub& stub, const std::string& name) {
  grpc::ClientContext context;
  v1::CreateSessionRequest request;
  request.set_display_name(name);
  v1::CreateSessionResponse response;
  grpc::Status status = stub.CreateSession(&context, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return response.session();
}

grpc::Status Rename(v1::Inbetween::Stub& stub, const v1::Session& session,
                    v1::PutDrawingResponse* response) {
  grpc::ClientContext context;
  v1::PutDrawingRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  *request.mutable_drawing()->mutable_polylines()->add_elements() = SquareOutline(0, 0, 1);
  return stub.PutDrawing(&context, request, response);
}

TEST(StoreServerTest, IdleSessionsAreEvictedFromMemoryAndReloadOnTheNextCall) {
  const fs::path root = fs::temp_directory_path() / ("idle_evict_test_" + std::to_string(getpid()));
  fs::remove_all(root);
  {
    auto server = StartWithStore("dir:" + root.string(), std::chrono::seconds(1));
    ASSERT_TRUE(server);
    auto stub = v1::Inbetween::NewStub(server->InProcessChannel());
    const v1::Session session = Create(*stub, "idle");
    EXPECT_EQ(server->store().CachedCount(), 1u);
    // Bounded poll (generous; the sweep runs every 250 ms with a 1 s idle time).
    for (int i = 0; i < 200 && server->store().CachedCount() != 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_EQ(server->store().CachedCount(), 0u) << "the idle session stayed in memory";
    EXPECT_EQ(server->store().Count(), 1u);
    EXPECT_NE(server->RenderMetrics().find("\ninbetween_cached_sessions 0\n"), std::string::npos)
        << server->RenderMetrics();
    grpc::ClientContext context;
    v1::GetSessionRequest request;
    request.set_session_id(session.id());
    v1::GetSessionResponse response;
    ASSERT_TRUE(stub->GetSession(&context, request, &response).ok());
    EXPECT_EQ(response.session().display_name(), "idle");
    EXPECT_EQ(server->store().CachedCount(), 1u);
  }
  fs::remove_all(root);
}

TEST(StoreServerTest, ZeroIdleEvictKeepsSessionsInMemory) {
  const fs::path root = fs::temp_directory_path() / ("no_evict_test_" + std::to_string(getpid()));
  fs::remove_all(root);
  {
    auto server = StartWithStore("dir:" + root.string(), std::chrono::seconds(0));
    ASSERT_TRUE(server);
    auto stub = v1::Inbetween::NewStub(server->InProcessChannel());
    Create(*stub, "kept");
    EXPECT_EQ(server->store().EvictIdle(std::chrono::steady_clock::now() - std::chrono::hours(1)),
              0u);
    EXPECT_EQ(server->store().CachedCount(), 1u);
  }
  fs::remove_all(root);
}

TEST(StoreServerTest, TwoServersOverOneRedisShareSessionsAndVersions) {
  const std::string binary = FindRedisServer();
  if (binary.empty()) GTEST_SKIP() << "redis-server is not installed";
  RedisProcess redis(binary);
  ASSERT_FALSE(redis.url().empty());
  auto a = StartWithStore(redis.url(), std::chrono::seconds(600));
  auto b = StartWithStore(redis.url(), std::chrono::seconds(600));
  ASSERT_TRUE(a && b);
  auto stub_a = v1::Inbetween::NewStub(a->InProcessChannel());
  auto stub_b = v1::Inbetween::NewStub(b->InProcessChannel());
  const v1::Session session = Create(*stub_a, "shared");

  v1::PutDrawingResponse on_b;
  grpc::Status status = Rename(*stub_b, session, &on_b);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(on_b.session().version(), session.version() + 1);
  // The same version again, now through a: stale, ABORTED, nothing written.
  v1::PutDrawingResponse on_a;
  EXPECT_EQ(Rename(*stub_a, session, &on_a).error_code(), grpc::StatusCode::ABORTED);

  grpc::ClientContext context;
  v1::ListSessionsRequest list;
  v1::ListSessionsResponse listed;
  ASSERT_TRUE(stub_a->ListSessions(&context, list, &listed).ok());
  ASSERT_EQ(listed.sessions_size(), 1);
  EXPECT_EQ(listed.sessions(0).version(), session.version() + 1);

  grpc::ClientContext delete_context;
  v1::DeleteSessionRequest request;
  request.set_session_id(session.id());
  v1::DeleteSessionResponse deleted;
  ASSERT_TRUE(stub_a->DeleteSession(&delete_context, request, &deleted).ok());
  grpc::ClientContext get_context;
  v1::GetSessionRequest get;
  get.set_session_id(session.id());
  v1::GetSessionResponse got;
  EXPECT_EQ(stub_b->GetSession(&get_context, get, &got).error_code(), grpc::StatusCode::NOT_FOUND);
}

}  // namespace
}  // namespace inbetween::server::testing
