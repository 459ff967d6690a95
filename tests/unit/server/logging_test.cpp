// ConfigureLogging: accepted values and errors naming the flag; LogRpc's JSON lines: the RPC's
// fields as JSON fields, user text escaped.
#include "server/logging.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace inbetween::server {
namespace {

using ::testing::HasSubstr;

TEST(LoggingTest, AcceptsDocumentedValues) {
  for (const char* level : {"trace", "debug", "info", "warn", "error", "off"}) {
    EXPECT_TRUE(ConfigureLogging(level, "text").ok()) << level;
  }
  EXPECT_TRUE(ConfigureLogging("info", "json").ok());
  spdlog::info("a message with \"quotes\" and a\nnewline stays one JSON line");
  EXPECT_TRUE(ConfigureLogging("warn", "text").ok());
}

TEST(LoggingTest, BadValuesNameTheFlag) {
  absl::Status level = ConfigureLogging("loud", "text");
  EXPECT_EQ(level.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(level.message()), HasSubstr("--log-level"));
  absl::Status format = ConfigureLogging("info", "xml");
  EXPECT_EQ(format.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(format.message()), HasSubstr("--log-format"));
}

// The lines `log` writes with ConfigureLogging(level, format) in effect, one string per line.
template <typename Log>
std::vector<std::string> LinesOf(const char* level, const char* format, Log log) {
  EXPECT_TRUE(ConfigureLogging(level, format).ok());
  std::ostringstream out;
  auto logger = std::make_shared<spdlog::logger>(
      "capture", std::make_shared<spdlog::sinks::ostream_sink_st>(out));
  spdlog::initialize_logger(logger);  // takes the formatter ConfigureLogging set
  spdlog::set_default_logger(logger);
  log();
  spdlog::drop("capture");
  EXPECT_TRUE(ConfigureLogging("warn", "text").ok());  // back to the server's logger
  std::vector<std::string> lines;
  std::istringstream in(out.str());
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(LoggingTest, JsonRpcLinesCarryTheirFields) {
  // A session id and an error message with a quote, a backslash, a newline, a control character
  // and a byte that is not UTF-8; one accented letter that is.
  const std::string session = "s\"1\\\n\x01\xff-\xc3\xa9";
  const std::vector<std::string> lines = LinesOf("info", "json", [&] {
    LogRpc("req-1", "GetSession", session,
           grpc::Status(grpc::StatusCode::NOT_FOUND, "session " + session + " not found"), 0.25);
    LogRpc("req-2", "CreateSession", "", grpc::Status::OK, 0.001);
    LogRpc("req-3", "ListSessions", "", grpc::Status::OK, 0.001, /*ok_at_info=*/false);  // debug
    spdlog::info("plain");
  });
  ASSERT_EQ(lines.size(), 3u);
  const std::string expected_session = "s\"1\\\n\x01\xef\xbf\xbd-\xc3\xa9";  // 0xff -> U+FFFD

  const nlohmann::json failed = nlohmann::json::parse(lines[0]);
  EXPECT_EQ(failed["level"], "warning");
  EXPECT_EQ(failed["request"], "req-1");
  EXPECT_EQ(failed["method"], "GetSession");
  EXPECT_EQ(failed["session"], expected_session);
  EXPECT_EQ(failed["status"], "NOT_FOUND");
  ASSERT_TRUE(failed["seconds"].is_number());
  EXPECT_DOUBLE_EQ(failed["seconds"].get<double>(), 0.25);
  EXPECT_EQ(failed["error"], "session " + expected_session + " not found");
  EXPECT_THAT(failed["msg"].get<std::string>(), HasSubstr("GetSession NOT_FOUND"));

  const nlohmann::json ok = nlohmann::json::parse(lines[1]);
  EXPECT_EQ(ok["method"], "CreateSession");
  EXPECT_EQ(ok["status"], "OK");
  EXPECT_FALSE(ok.contains("session"));
  EXPECT_FALSE(ok.contains("error"));

  // A line that is not an RPC's has the four fields only.
  const nlohmann::json plain = nlohmann::json::parse(lines[2]);
  EXPECT_EQ(plain.size(), 4u) << lines[2];
  EXPECT_EQ(plain["msg"], "plain");
}

TEST(LoggingTest, TextRpcLinesKeepTheirFormat) {
  const std::vector<std::string> lines = LinesOf("info", "text", [] {
    LogRpc("req-1", "GetSession", "abc",
           grpc::Status(grpc::StatusCode::NOT_FOUND, "session abc not found"), 0.25);
    LogRpc("req-2", "CreateSession", "", grpc::Status::OK, 0.001);
  });
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_THAT(lines[0], HasSubstr("[warning] request=req-1 rpc=GetSession session=abc "
                                  "status=NOT_FOUND seconds=0.250 error=session abc not found"));
  EXPECT_THAT(lines[1],
              HasSubstr("[info] request=req-2 rpc=CreateSession status=OK seconds=0.001"));
}

}  // namespace
}  // namespace inbetween::server
