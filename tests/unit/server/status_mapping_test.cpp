// ToGrpcStatus: every absl code maps to the grpc code of the same name; messages pass through;
// reasons, offending fields and retry delays travel as google.rpc-compatible details.
#include "server/status_mapping.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

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

// The details of a mapped status, by type URL (empty when absent).
std::map<std::string, std::string> DetailsOf(const grpc::Status& status) {
  std::map<std::string, std::string> out;
  inbetween::v1::ErrorStatus details;
  if (status.error_details().empty() || !details.ParseFromString(status.error_details())) {
    return out;
  }
  for (const auto& detail : details.details()) out[detail.type_url()] = detail.value();
  return out;
}

TEST(StatusMappingTest, TheOffendingFieldIsARequestFieldPath) {
  EXPECT_EQ(OffendingField("parameters.frames = 1 is not in [2, 1000]"), "parameters.frames");
  EXPECT_EQ(OffendingField("drawing.svg is empty"), "drawing.svg");
  EXPECT_EQ(OffendingField("topology[2].polyline.points has 1 point"),
            "topology[2].polyline.points");
  EXPECT_EQ(OffendingField("session_id is required"), "session_id");
  EXPECT_EQ(OffendingField("flatten_tolerance = -1 is not in (0, 1e6]"), "flatten_tolerance");
  // Not fields of any request: no path.
  EXPECT_EQ(OffendingField("edit 3 names drawing 9"), "");
  EXPECT_EQ(OffendingField("the drawings differ"), "");
  EXPECT_EQ(OffendingField("session_id[1] is not repeated"), "");
  EXPECT_EQ(OffendingField("parameters.nothing = 1"), "");
  EXPECT_EQ(OffendingField(""), "");
}

TEST(StatusMappingTest, AFieldTravelsAsBadRequestAndADelayAsRetryInfo) {
  const grpc::Status bad =
      ToGrpcStatus(absl::InvalidArgumentError("parameters.frames = 1 is not in [2, 1000]"));
  auto details = DetailsOf(bad);
  ASSERT_EQ(details.count("type.googleapis.com/google.rpc.BadRequest"), 1u);
  inbetween::v1::BadRequest request;
  ASSERT_TRUE(request.ParseFromString(details["type.googleapis.com/google.rpc.BadRequest"]));
  ASSERT_EQ(request.field_violations_size(), 1);
  EXPECT_EQ(request.field_violations(0).field(), "parameters.frames");
  EXPECT_EQ(request.field_violations(0).description(), bad.error_message());
  // Only for the argument codes.
  EXPECT_TRUE(DetailsOf(ToGrpcStatus(absl::NotFoundError("session_id x"))).empty());

  const grpc::Status busy = ToGrpcStatus(solver::WithRetryAfter(
      solver::WithReason(absl::ResourceExhaustedError("busy"), solver::kReasonServerBusy), 2500));
  details = DetailsOf(busy);
  ASSERT_EQ(details.size(), 2u);
  inbetween::v1::RetryInfo retry;
  ASSERT_TRUE(retry.ParseFromString(details["type.googleapis.com/google.rpc.RetryInfo"]));
  EXPECT_EQ(retry.retry_delay().seconds(), 2);
  EXPECT_EQ(retry.retry_delay().nanos(), 500'000'000);
  inbetween::v1::ErrorInfo info;
  ASSERT_TRUE(info.ParseFromString(details["type.googleapis.com/google.rpc.ErrorInfo"]));
  EXPECT_EQ(info.reason(), "SERVER_BUSY");
}

}  // namespace
}  // namespace inbetween::server
