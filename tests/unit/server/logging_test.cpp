// ConfigureLogging: accepted values and errors naming the flag.
#include "server/logging.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

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

}  // namespace
}  // namespace inbetween::server
