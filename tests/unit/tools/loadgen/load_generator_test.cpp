// Tests inbetween-loadgen's engine (tools/loadgen/load_generator.cpp): loopback-only targets,
// nearest-rank percentiles, and a bounded run against a real in-process server that stops at
// exactly the request budget, exercises every RPC of the studio loop without errors, loses no
// session and gets the same frames from every stream.
#include "tools/loadgen/load_generator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "nlohmann/json.hpp"
#include "server/inbetween_server.h"

namespace inbetween::loadgen {
namespace {

using ::testing::HasSubstr;

std::string ReadExample(const std::string& relative) {
  std::ifstream in(std::string(INBETWEEN_SOURCE_DIR) + "/" + relative);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(LoadGeneratorTest, OnlyLoopbackTargets) {
  for (const char* ok : {"127.0.0.1:50051", "127.1.2.3:1", "localhost:8080", "[::1]:443"}) {
    EXPECT_TRUE(CheckLoopbackTarget(ok).ok()) << ok;
  }
  for (const char* bad : {"10.0.0.1:50051", "example.com:443", "0.0.0.0:1", "[2001:db8::1]:1",
                          "127.0.0.1", "127.0.0.1:0", "127.0.0.1:99999", "128.0.0.1:1"}) {
    EXPECT_FALSE(CheckLoopbackTarget(bad).ok()) << bad;
  }
  EXPECT_THAT(CheckLoopbackTarget("192.168.1.2:50051").message(), HasSubstr("not a loopback"));
}

TEST(LoadGeneratorTest, NearestRankPercentiles) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);  // 1..100, unsorted
  EXPECT_EQ(Percentile(v, 50), 50);
  EXPECT_EQ(Percentile(v, 95), 95);
  EXPECT_EQ(Percentile(v, 99), 99);
  EXPECT_EQ(Percentile(v, 100), 100);
  EXPECT_EQ(Percentile({7}, 99), 7);
  EXPECT_EQ(Percentile({}, 50), 0);
}

TEST(LoadGeneratorTest, BoundedRunAgainstARealServer) {
  // Room for every studio's heavy call at once: no RESOURCE_EXHAUSTED back-pressure here.
  server::ServerOptions server_options;
  server_options.service.heavy.max_running = 3;
  server_options.service.heavy.max_per_owner = 3;
  auto server = server::InbetweenServer::Start(server_options);
  ASSERT_TRUE(server.ok()) << server.status();
  LoadGenOptions options;
  options.studios = 3;
  options.duration = std::chrono::seconds(600);  // the request budget ends the run
  options.max_requests = 60;
  options.frames = 6;
  options.drawings_svg = {ReadExample("examples/square_hexagon/square.svg"),
                          ReadExample("examples/square_hexagon/hexagon.svg")};
  auto report = RunLoad((*server)->InProcessChannel(), options);
  ASSERT_TRUE(report.ok()) << report.status();

  EXPECT_EQ(report->requests, 60);
  EXPECT_EQ(report->errors, 0) << FormatTable(*report);
  EXPECT_TRUE(report->errors_by_code.empty());
  for (const char* rpc : {"CreateSession", "PutDrawing", "BuildMultimesh", "OptimizeComesh",
                          "Inbetween", "GetSession", "ListSessions", "DeleteSession"}) {
    ASSERT_TRUE(report->rpcs.count(rpc)) << rpc << "\n" << FormatTable(*report);
    EXPECT_GT(report->rpcs.at(rpc).calls, 0) << rpc;
    EXPECT_LE(report->rpcs.at(rpc).p50_ms, report->rpcs.at(rpc).p99_ms) << rpc;
  }
  int64_t calls = 0;
  for (const auto& [rpc, s] : report->rpcs) calls += s.calls;
  EXPECT_EQ(calls, 60);
  EXPECT_EQ(report->sessions, report->rpcs.at("CreateSession").calls);
  EXPECT_EQ(report->lost_sessions, 0);
  EXPECT_EQ(report->streams_completed, report->rpcs.at("Inbetween").calls);
  EXPECT_TRUE(report->frames_identical);

  // The JSON carries the fields scripts and dashboards read.
  nlohmann::json j = nlohmann::json::parse(FormatJson(*report));
  EXPECT_EQ(j["studios"], 3);
  EXPECT_EQ(j["requests"], 60);
  EXPECT_EQ(j["lost_sessions"], 0);
  EXPECT_EQ(j["frames_identical"], true);
  EXPECT_TRUE(j["errors_by_code"].is_object());
  EXPECT_TRUE(j["rpcs"].contains("Inbetween"));
  EXPECT_GT(j["unary_p99_ms"].get<double>(), 0.0);
}

TEST(LoadGeneratorTest, UnreachableTargetIsCountedByCode) {
  LoadGenOptions options;
  options.studios = 1;
  options.max_requests = 3;
  options.drawings_svg = {"<svg/>", "<svg/>"};
  // A port nobody listens on: 127.0.0.1:1 (privileged, unused).
  auto report =
      RunLoad(grpc::CreateChannel("127.0.0.1:1", grpc::InsecureChannelCredentials()), options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->requests, 3);
  EXPECT_EQ(report->errors_by_code["UNAVAILABLE"], 3);
  EXPECT_EQ(report->rpcs["CreateSession"].errors_by_code["UNAVAILABLE"], 3);
  EXPECT_EQ(report->sessions, 0);
}

}  // namespace
}  // namespace inbetween::loadgen
