// absl::Status -> grpc::Status, code for code, message unchanged, a reason as ErrorInfo details.
#include "server/status_mapping.h"

#include <string>

#include "inbetween/v1/inbetween.pb.h"
#include "solver/core/error_reason.h"

namespace inbetween::server {
namespace {

grpc::StatusCode ToGrpcCode(absl::StatusCode code) {
  switch (code) {
    case absl::StatusCode::kOk:
      return grpc::StatusCode::OK;
    case absl::StatusCode::kCancelled:
      return grpc::StatusCode::CANCELLED;
    case absl::StatusCode::kUnknown:
      return grpc::StatusCode::UNKNOWN;
    case absl::StatusCode::kInvalidArgument:
      return grpc::StatusCode::INVALID_ARGUMENT;
    case absl::StatusCode::kDeadlineExceeded:
      return grpc::StatusCode::DEADLINE_EXCEEDED;
    case absl::StatusCode::kNotFound:
      return grpc::StatusCode::NOT_FOUND;
    case absl::StatusCode::kAlreadyExists:
      return grpc::StatusCode::ALREADY_EXISTS;
    case absl::StatusCode::kPermissionDenied:
      return grpc::StatusCode::PERMISSION_DENIED;
    case absl::StatusCode::kResourceExhausted:
      return grpc::StatusCode::RESOURCE_EXHAUSTED;
    case absl::StatusCode::kFailedPrecondition:
      return grpc::StatusCode::FAILED_PRECONDITION;
    case absl::StatusCode::kAborted:
      return grpc::StatusCode::ABORTED;
    case absl::StatusCode::kOutOfRange:
      return grpc::StatusCode::OUT_OF_RANGE;
    case absl::StatusCode::kUnimplemented:
      return grpc::StatusCode::UNIMPLEMENTED;
    case absl::StatusCode::kInternal:
      return grpc::StatusCode::INTERNAL;
    case absl::StatusCode::kUnavailable:
      return grpc::StatusCode::UNAVAILABLE;
    case absl::StatusCode::kDataLoss:
      return grpc::StatusCode::DATA_LOSS;
    case absl::StatusCode::kUnauthenticated:
      return grpc::StatusCode::UNAUTHENTICATED;
    default:  // absl's reserved placeholder enumerator asks for a default
      break;
  }
  // absl reserves the right to add codes; an unknown one is a bug on our side, not the client's.
  return grpc::StatusCode::UNKNOWN;
}

}  // namespace

grpc::Status ToGrpcStatus(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  const grpc::StatusCode code = ToGrpcCode(status.code());
  const std::string reason = solver::ErrorReason(status);
  if (reason.empty()) return grpc::Status(code, std::string(status.message()));
  inbetween::v1::ErrorInfo info;
  info.set_reason(reason);
  info.set_domain(std::string(solver::kErrorDomain));
  inbetween::v1::ErrorStatus details;
  details.set_code(static_cast<int32_t>(code));
  details.set_message(std::string(status.message()));
  inbetween::v1::ErrorDetail* detail = details.add_details();
  detail->set_type_url(std::string(solver::kErrorInfoTypeUrl));
  detail->set_value(info.SerializeAsString());
  return grpc::Status(code, std::string(status.message()), details.SerializeAsString());
}

}  // namespace inbetween::server
