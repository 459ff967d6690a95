// Bearer tokens (--tokens): UNAUTHENTICATED without a valid token, sessions owned by their token
// (another token sees NOT_FOUND, lists only its own), health open; limits with their flags;
// metrics text (prometheus-cpp's exposition: label names in sorted order) and the /metrics
// endpoint (prometheus-cpp's Exposer) with its --metrics-listen errors.
#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <grpcpp/client_context.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "server/auth.h"
#include "server/metrics.h"
#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

using ::testing::HasSubstr;

TEST(TokenTableTest, ParsesTokensWithOptionalNames) {
  auto table = TokenTable::Parse("# comment\n\nsecret-a alice\nsecret-b\n", "tokens");
  ASSERT_TRUE(table.ok()) << table.status();
  EXPECT_EQ(table->size(), 2u);
  EXPECT_EQ(*table->Owner("Bearer secret-a"), "alice");
  EXPECT_THAT(*table->Owner("bearer secret-b"), HasSubstr("token-"));
  EXPECT_EQ(table->Owner("").status().code(), absl::StatusCode::kUnauthenticated);
  EXPECT_EQ(table->Owner("Bearer nope").status().code(), absl::StatusCode::kUnauthenticated);
  EXPECT_EQ(table->Owner("Basic secret-a").status().code(), absl::StatusCode::kUnauthenticated);
  EXPECT_THAT(TokenTable::Parse("a b c\n", "tokens").status().message(), HasSubstr("line 1"));
  EXPECT_THAT(TokenTable::Parse("a\na\n", "tokens").status().message(), HasSubstr("repeated"));
}

TEST(MetricsTest, RendersCountersHistogramsAndGauges) {
  Metrics metrics;
  metrics.ObserveRpc("GetSession", "OK", 0.002);
  metrics.ObserveRpc("GetSession", "NOT_FOUND", 0.2);
  metrics.ObserveStage("build", 1.5);
  const std::string text = metrics.Render({{"inbetween_active_sessions", "Sessions.", 3}});
  EXPECT_THAT(text, HasSubstr("# TYPE inbetween_rpcs_total counter"));
  EXPECT_THAT(text, HasSubstr("inbetween_rpcs_total{code=\"OK\",method=\"GetSession\"} 1"));
  EXPECT_THAT(text, HasSubstr("inbetween_rpcs_total{code=\"NOT_FOUND\",method=\"GetSession\"} 1"));
  // Latency per method and status code: the fast OK call and the slow NOT_FOUND one apart.
  const std::string ok = "inbetween_rpc_duration_seconds_bucket{code=\"OK\",method=\"GetSession\",";
  const std::string missing =
      "inbetween_rpc_duration_seconds_bucket{code=\"NOT_FOUND\",method=\"GetSession\",";
  EXPECT_THAT(text, HasSubstr(ok + "le=\"0.005\"} 1"));
  EXPECT_THAT(text, HasSubstr(ok + "le=\"+Inf\"} 1"));
  EXPECT_THAT(text, HasSubstr(missing + "le=\"0.1\"} 0"));
  EXPECT_THAT(text, HasSubstr(missing + "le=\"0.25\"} 1"));
  EXPECT_THAT(
      text,
      HasSubstr(
          "inbetween_rpc_duration_seconds_count{code=\"NOT_FOUND\",method=\"GetSession\"} 1"));
  EXPECT_THAT(text, HasSubstr("inbetween_stage_seconds_bucket{stage=\"build\",le=\"1\"} 0"));
  EXPECT_THAT(text, HasSubstr("inbetween_stage_seconds_bucket{stage=\"build\",le=\"5\"} 1"));
  EXPECT_THAT(text, HasSubstr("inbetween_stage_seconds_count{stage=\"build\"} 1"));
  EXPECT_THAT(text, HasSubstr("inbetween_stage_seconds_sum{stage=\"build\"} 1.5"));
  EXPECT_THAT(text, HasSubstr("inbetween_frames_solved_total 0"));
  EXPECT_THAT(text,
              HasSubstr("# TYPE inbetween_active_sessions gauge\ninbetween_active_sessions 3\n"));
  metrics.CountFrameSolved();
  EXPECT_EQ(metrics.frames_solved(), 1u);
  EXPECT_THAT(metrics.Render({}), HasSubstr("inbetween_frames_solved_total 1"));
}

TEST(MetricsHttpServerTest, BadAddressesNameTheFlag) {
  const auto metrics = std::make_shared<Metrics>();
  const auto no_gauges = [] { return std::vector<Metrics::Gauge>{}; };
  // Not HOST:PORT, no such port, IPv6 (Debian's civetweb is built without it).
  for (const char* listen : {"9090", ":9090", "127.0.0.1:notaport", "[::1]:0", "[::]:9090"}) {
    auto server = MetricsHttpServer::Start(listen, metrics, no_gauges);
    ASSERT_FALSE(server.ok()) << listen;
    EXPECT_EQ(server.status().code(), absl::StatusCode::kInvalidArgument) << listen;
    EXPECT_THAT(std::string(server.status().message()), HasSubstr("--metrics-listen")) << listen;
  }
  // A port that is taken (by the first server) and an address of no local interface.
  auto first = MetricsHttpServer::Start("127.0.0.1:0", metrics, no_gauges);
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_GT((*first)->port(), 0);
  for (const std::string listen :
       {"127.0.0.1:" + std::to_string((*first)->port()), std::string("192.0.2.1:0")}) {
    auto server = MetricsHttpServer::Start(listen, metrics, no_gauges);
    ASSERT_FALSE(server.ok()) << listen;
    EXPECT_EQ(server.status().code(), absl::StatusCode::kUnavailable) << listen;
    EXPECT_THAT(std::string(server.status().message()), HasSubstr("--metrics-listen")) << listen;
  }
}

// GET `path` from 127.0.0.1:port; the whole response.
std::string HttpGet(int port, const std::string& path) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd);
    return "";
  }
  const std::string request = "GET " + path + " HTTP/1.1\r\nHost: x\r\n\r\n";
  (void)!write(fd, request.data(), request.size());
  std::string response;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fd, buffer, sizeof(buffer))) > 0) response.append(buffer, n);
  close(fd);
  return response;
}

class SecuredServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tokens_ =
        std::filesystem::temp_directory_path() / ("tokens_" + std::to_string(getpid()) + ".txt");
    std::ofstream(tokens_) << "token-a alice\ntoken-b bob\n";
    ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.metrics_listen = "127.0.0.1:0";
    options.tokens_file = tokens_.string();
    options.shutdown_grace = std::chrono::milliseconds(200);
    options.service.limits.max_sessions_per_token = 2;
    options.service.limits.max_frames = 10;
    auto server = InbetweenServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = *std::move(server);
    channel_ = server_->InProcessChannel();
    stub_ = v1::Inbetween::NewStub(channel_);
  }
  void TearDown() override { std::filesystem::remove(tokens_); }

  void Authorize(grpc::ClientContext* context, const std::string& token) {
    if (!token.empty()) context->AddMetadata("authorization", "Bearer " + token);
  }

  grpc::Status Create(const std::string& token, v1::Session* session) {
    grpc::ClientContext context;
    Authorize(&context, token);
    v1::CreateSessionRequest request;
    v1::CreateSessionResponse response;
    grpc::Status status = stub_->CreateSession(&context, request, &response);
    *session = response.session();
    return status;
  }

  grpc::Status Get(const std::string& token, const std::string& id) {
    grpc::ClientContext context;
    Authorize(&context, token);
    v1::GetSessionRequest request;
    request.set_session_id(id);
    v1::GetSessionResponse response;
    return stub_->GetSession(&context, request, &response);
  }

  std::filesystem::path tokens_;
  std::unique_ptr<InbetweenServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Inbetween::Stub> stub_;
};

TEST_F(SecuredServerTest, TokensOwnSessions) {
  v1::Session session;
  EXPECT_EQ(Create("", &session).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Create("wrong", &session).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  ASSERT_TRUE(Create("token-a", &session).ok());
  const std::string id = session.id();
  EXPECT_TRUE(Get("token-a", id).ok());
  grpc::Status other = Get("token-b", id);
  EXPECT_EQ(other.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(other.error_message(), Get("token-b", "does-not-exist")
                                       .error_message()
                                       .replace(8, std::string("does-not-exist").size(), id));
  EXPECT_EQ(Get("", id).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  {
    grpc::ClientContext context;
    Authorize(&context, "token-b");
    v1::DeleteSessionRequest request;
    request.set_session_id(id);
    v1::DeleteSessionResponse response;
    EXPECT_EQ(stub_->DeleteSession(&context, request, &response).error_code(),
              grpc::StatusCode::NOT_FOUND);
  }
  v1::Session b;
  ASSERT_TRUE(Create("token-b", &b).ok());
  for (const auto& [token, expected] : {std::pair{"token-a", id}, {"token-b", b.id()}}) {
    grpc::ClientContext context;
    Authorize(&context, token);
    v1::ListSessionsRequest request;
    v1::ListSessionsResponse response;
    ASSERT_TRUE(stub_->ListSessions(&context, request, &response).ok());
    ASSERT_EQ(response.sessions_size(), 1) << token;
    EXPECT_EQ(response.sessions(0).id(), expected);
  }
  // --max-sessions-per-token = 2.
  ASSERT_TRUE(Create("token-a", &session).ok());
  grpc::Status full = Create("token-a", &session);
  EXPECT_EQ(full.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(full.error_message(), HasSubstr("--max-sessions-per-token"));

  // Health needs no token.
  EXPECT_EQ(HealthCheck(channel_, "inbetween.v1.Inbetween"), 1);
}

TEST_F(SecuredServerTest, FrameLimitAndMetricsEndpoint) {
  v1::Session session;
  ASSERT_TRUE(Create("token-a", &session).ok());
  grpc::ClientContext context;
  Authorize(&context, "token-a");
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(11);
  auto reader = stub_->Inbetween(&context, request);
  v1::InbetweenResponse message;
  while (reader->Read(&message)) {
  }
  // The stage check comes first for a session without a multimesh.
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::FAILED_PRECONDITION);

  // Served by civetweb's threads in a process holding OpenBLAS's and METIS's static TLS: they
  // overflowed their stack before metrics.cpp's pthread_attr_setstacksize made room for it.
  ASSERT_GT(server_->metrics_port(), 0);
  const std::string metrics = HttpGet(server_->metrics_port(), "/metrics");
  EXPECT_THAT(metrics, HasSubstr("HTTP/1.1 200 OK"));
  EXPECT_THAT(metrics, HasSubstr("inbetween_rpcs_total{code=\"OK\",method=\"CreateSession\"} 1"));
  EXPECT_THAT(metrics, HasSubstr("code=\"FAILED_PRECONDITION\""));
  EXPECT_THAT(metrics, HasSubstr("# TYPE inbetween_active_sessions gauge"));
  EXPECT_THAT(metrics, HasSubstr("inbetween_active_sessions 1"));
  EXPECT_THAT(metrics, HasSubstr("inbetween_heavy_queue_depth 0"));
  EXPECT_THAT(HttpGet(server_->metrics_port(), "/other"), HasSubstr("404"));

  // The next scrape sees the next call counted and the gauge read anew.
  ASSERT_TRUE(Create("token-a", &session).ok());
  const std::string after = HttpGet(server_->metrics_port(), "/metrics");
  EXPECT_THAT(after, HasSubstr("inbetween_rpcs_total{code=\"OK\",method=\"CreateSession\"} 2"));
  EXPECT_THAT(after, HasSubstr("inbetween_active_sessions 2"));
}

// Many clients at once through the real gRPC server (its handler threads): every call gets its
// owner's answer (a session of the other token is NOT_FOUND), every call is counted once in the
// metrics, which another thread renders meanwhile. Under scripts/sanitize tsan (instrumented gRPC
// and Abseil) this is the handlers' shared state (token table, session store, metrics) checked for
// races across gRPC's threads.
TEST_F(SecuredServerTest, ConcurrentCallsGetTheirOwnersAnswersAndAreAllCounted) {
  v1::Session a, b;
  ASSERT_TRUE(Create("token-a", &a).ok());
  ASSERT_TRUE(Create("token-b", &b).ok());
  constexpr int kClients = 4, kRounds = 25;
  std::atomic<int> wrong{0}, renders{0};
  std::atomic<bool> done{false};
  std::thread renderer([&] {
    while (!done.load()) {
      if (HttpGet(server_->metrics_port(), "/metrics").find("200 OK") != std::string::npos) {
        ++renders;
      }
    }
  });
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c) {
    clients.emplace_back([&, c] {
      const bool is_a = c % 2 == 0;
      const std::string token = is_a ? "token-a" : "token-b";
      const std::string own = is_a ? a.id() : b.id(), other = is_a ? b.id() : a.id();
      for (int r = 0; r < kRounds; ++r) {
        if (!Get(token, own).ok()) ++wrong;
        if (Get(token, other).error_code() != grpc::StatusCode::NOT_FOUND) ++wrong;
      }
    });
  }
  for (std::thread& t : clients) t.join();
  done = true;
  renderer.join();
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_GT(renders.load(), 0);
  const std::string metrics = HttpGet(server_->metrics_port(), "/metrics");
  const std::string total = std::to_string(kClients * kRounds);
  EXPECT_THAT(metrics,
              HasSubstr("inbetween_rpcs_total{code=\"OK\",method=\"GetSession\"} " + total));
  EXPECT_THAT(metrics,
              HasSubstr("inbetween_rpcs_total{code=\"NOT_FOUND\",method=\"GetSession\"} " + total));
}

}  // namespace
}  // namespace inbetween::server::testing
