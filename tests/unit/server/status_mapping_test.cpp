// ToGrpcStatus: every absl code maps to the grpc code of the same name; messages pass through.
#include "server/status_mapping.h"

#include <gtest/gtest.h>

namespace inbetween::server {
namespace {

TEST(StatusMappingTest, MapsEveryCodeToTheSameNamedGrpcCode) {
  for (int code = 0; code <= 16; ++code) {
    const auto absl_code = static_cast<absl::StatusCode>(code);
    grpc::Status status = ToGrpcStatus(absl::Status(absl_code, "why"));
    EXPECT_EQ(static_cast<int>(status.error_code()), code) << absl::StatusCodeToString(absl_code);
    if (code != 0) EXPECT_EQ(status.error_message(), "why");
  }
}

TEST(StatusMappingTest, NamedExamples) {
  EXPECT_EQ(ToGrpcStatus(absl::AbortedError("x")).error_code(), grpc::StatusCode::ABORTED);
  EXPECT_EQ(ToGrpcStatus(absl::FailedPreconditionError("x")).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_EQ(ToGrpcStatus(absl::UnauthenticatedError("x")).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(ToGrpcStatus(absl::OkStatus()).ok());
}

}  // namespace
}  // namespace inbetween::server
