// InbetweenServer with persistent stores: idle sessions leave memory (--idle-evict-seconds) and
// reload on the next call; two servers over one Redis act as replicas through real RPCs (an
// optimization interrupted on one resumes on the other from the checkpoint in Redis).
#include <google/protobuf/util/message_differencer.h>
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

// A restarted server lists a dir store's sessions from their heads (nothing else loaded): the
// summaries still count the drawings.
TEST(StoreServerTest, ListingAfterARestartCountsTheDrawings) {
  const fs::path root = fs::temp_directory_path() / ("list_count_test_" + std::to_string(getpid()));
  fs::remove_all(root);
  std::string id;
  {
    auto server = StartWithStore("dir:" + root.string(), std::chrono::seconds(0));
    ASSERT_TRUE(server);
    auto stub = v1::Inbetween::NewStub(server->InProcessChannel());
    v1::PutDrawingResponse put;
    ASSERT_TRUE(Rename(*stub, Create(*stub, "one"), &put).ok());
    id = put.session().id();
  }
  {
    auto server = StartWithStore("dir:" + root.string(), std::chrono::seconds(0));
    ASSERT_TRUE(server);
    EXPECT_EQ(server->store().CachedCount(), 0u);
    auto stub = v1::Inbetween::NewStub(server->InProcessChannel());
    grpc::ClientContext context;
    v1::ListSessionsResponse listed;
    ASSERT_TRUE(stub->ListSessions(&context, v1::ListSessionsRequest(), &listed).ok());
    ASSERT_EQ(listed.sessions_size(), 1);
    EXPECT_EQ(listed.sessions(0).id(), id);
    ASSERT_TRUE(listed.sessions(0).has_drawing_count());
    EXPECT_EQ(listed.sessions(0).drawing_count(), 1u);
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

// The square -> hexagon examples, built, through `stub`.
v1::Session BuiltExamples(v1::Inbetween::Stub& stub) {
  v1::Session session = Create(stub, "square-hexagon");
  for (const char* name : {"square", "hexagon"}) {
    grpc::ClientContext context;
    v1::PutDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.mutable_drawing()->set_name(name);
    request.mutable_drawing()->set_svg(
        ReadExample(std::string("examples/square_hexagon/") + name + ".svg"));
    v1::PutDrawingResponse response;
    grpc::Status status = stub.PutDrawing(&context, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    session = response.session();
  }
  grpc::ClientContext context;
  v1::BuildMultimeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  auto reader = stub.BuildMultimesh(&context, request);
  v1::BuildMultimeshResponse message;
  while (reader->Read(&message)) {
    if (message.has_result()) session = message.result().session();
  }
  EXPECT_TRUE(reader->Finish().ok());
  return session;
}

v1::OptimizeComeshRequest OptimizeRequest(const v1::Session& session, bool resume) {
  v1::OptimizeComeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  request.set_resume(resume);
  request.mutable_comesh()->set_max_outer_iterations(8);
  request.mutable_comesh()->set_max_inner_iterations(200);
  return request;
}

// Runs the optimization to its end, or (interrupt) cancels it at the first iteration after the
// first topology pass, whose checkpoint is stored by then.
grpc::Status Optimize(v1::Inbetween::Stub& stub, const v1::OptimizeComeshRequest& request,
                      bool interrupt, v1::OptimizeComeshResult* result) {
  grpc::ClientContext context;
  auto reader = stub.OptimizeComesh(&context, request);
  v1::OptimizeComeshResponse message;
  bool passed = false;
  while (reader->Read(&message)) {
    if (message.has_result()) *result = message.result();
    if (message.has_progress() && message.progress().detail().starts_with("outer ")) passed = true;
    if (interrupt && passed && message.has_iteration()) {
      context.TryCancel();
      break;
    }
  }
  while (reader->Read(&message)) {
  }
  return reader->Finish();
}

TEST(StoreServerTest, OptimizationInterruptedOnOneReplicaResumesOnAnotherOverRedis) {
  const std::string binary = FindRedisServer();
  if (binary.empty()) GTEST_SKIP() << "redis-server is not installed";
  RedisProcess redis(binary);
  ASSERT_FALSE(redis.url().empty());
  auto a = StartWithStore(redis.url(), std::chrono::seconds(600));
  auto b = StartWithStore(redis.url(), std::chrono::seconds(600));
  ASSERT_TRUE(a && b);
  auto stub_a = v1::Inbetween::NewStub(a->InProcessChannel());
  auto stub_b = v1::Inbetween::NewStub(b->InProcessChannel());

  v1::OptimizeComeshResult reference;
  const v1::Session reference_session = BuiltExamples(*stub_a);
  ASSERT_TRUE(Optimize(*stub_a, OptimizeRequest(reference_session, false), false, &reference).ok());
  ASSERT_GE(reference.outer_iterations(), 2u);

  const v1::Session session = BuiltExamples(*stub_a);
  {
    // b has the session cached at the version before the optimization.
    grpc::ClientContext context;
    v1::GetSessionRequest get;
    get.set_session_id(session.id());
    v1::GetSessionResponse got;
    ASSERT_TRUE(stub_b->GetSession(&context, get, &got).ok());
    EXPECT_EQ(got.session().version(), session.version());
  }
  v1::OptimizeComeshResult unused;
  EXPECT_EQ(Optimize(*stub_a, OptimizeRequest(session, false), true, &unused).error_code(),
            grpc::StatusCode::CANCELLED);
  a.reset();  // the replica goes away (after its grace period)

  v1::OptimizeComeshResult resumed;
  grpc::Status status = Optimize(*stub_b, OptimizeRequest(session, true), false, &resumed);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(resumed.resumed_outer(), 1u);
  EXPECT_GT(resumed.resumed_inner(), 0u);
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(resumed.multimesh(),
                                                                 reference.multimesh()));
  EXPECT_EQ(resumed.inner_iterations(), reference.inner_iterations());
  EXPECT_EQ(resumed.session().stage(), v1::STAGE_OPTIMIZED);
}

}  // namespace
}  // namespace inbetween::server::testing
