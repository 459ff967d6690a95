// ToGrpcStatus: every absl code maps to the grpc code of the same name; messages pass through.
#include "server/status_mapping.h"

#include <gtest/gtest.h>

#include "inbetween/v1/inbetween.pb.h"
#include "solver/core/error_reason.h"

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

// A reason becomes a google.rpc.ErrorInfo in the status details (ErrorStatus, wire-compatible).
TEST(StatusMappingTest, AReasonTravelsAsErrorInfoDetails) {
  const grpc::Status plain = ToGrpcStatus(absl::InvalidArgumentError("x"));
  EXPECT_TRUE(plain.error_details().empty());
  const grpc::Status status = ToGrpcStatus(
      solver::WithReason(absl::InvalidArgumentError("why"), solver::kReasonTopologyDiffers));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(status.error_message(), "why");
  inbetween::v1::ErrorStatus details;
  ASSERT_TRUE(details.ParseFromString(status.error_details()));
  EXPECT_EQ(details.code(), static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_EQ(details.message(), "why");
  ASSERT_EQ(details.details_size(), 1);
  EXPECT_EQ(details.details(0).type_url(), "type.googleapis.com/google.rpc.ErrorInfo");
  inbetween::v1::ErrorInfo info;
  ASSERT_TRUE(info.ParseFromString(details.details(0).value()));
  EXPECT_EQ(info.reason(), "TOPOLOGY_DIFFERS");
  EXPECT_EQ(info.domain(), "inbetween.v1");
}

}  // namespace
}  // namespace inbetween::server
