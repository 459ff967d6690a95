// absl::Status -> grpc::Status, code for code, message unchanged; a reason, the offending field
// and a retry delay as google.rpc-compatible status details.
#include "server/status_mapping.h"

#include <string>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
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

// Whether `path` ("parameters.frames", "drawings[1].svg") names a field of `message`: each
// component a field of the one before, an index only on a repeated field.
bool NamesField(const google::protobuf::Descriptor* message, absl::string_view path) {
  for (absl::string_view component : absl::StrSplit(path, '.')) {
    if (message == nullptr) return false;
    const size_t bracket = component.find('[');
    const google::protobuf::FieldDescriptor* field =
        message->FindFieldByName(std::string(component.substr(0, bracket)));
    if (field == nullptr || (bracket != absl::string_view::npos && !field->is_repeated())) {
      return false;
    }
    message = field->message_type();
  }
  return true;
}

}  // namespace

std::string OffendingField(absl::string_view message) {
  // The longest leading run of identifiers, dots and [digits]; a trailing dot is not part of it.
  size_t end = 0;
  while (end < message.size()) {
    const char c = message[end];
    const bool word = absl::ascii_islower(c) || absl::ascii_isdigit(c) || c == '_';
    if (!word && c != '.' && c != '[' && c != ']') break;
    ++end;
  }
  absl::string_view path = absl::StripSuffix(message.substr(0, end), ".");
  if (path.empty() || !absl::ascii_islower(path[0]) || absl::StrContains(path, "..")) return "";
  static const google::protobuf::ServiceDescriptor* service =
      google::protobuf::DescriptorPool::generated_pool()->FindServiceByName(
          "inbetween.v1.Inbetween");
  for (int i = 0; service != nullptr && i < service->method_count(); ++i) {
    if (NamesField(service->method(i)->input_type(), path)) return std::string(path);
  }
  return "";
}

grpc::Status ToGrpcStatus(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  const grpc::StatusCode code = ToGrpcCode(status.code());
  inbetween::v1::ErrorStatus details;
  const auto add = [&](absl::string_view type_url, const google::protobuf::Message& detail) {
    inbetween::v1::ErrorDetail* any = details.add_details();
    any->set_type_url(std::string(type_url));
    any->set_value(detail.SerializeAsString());
  };
  if (const std::string reason = solver::ErrorReason(status); !reason.empty()) {
    inbetween::v1::ErrorInfo info;
    info.set_reason(reason);
    info.set_domain(std::string(solver::kErrorDomain));
    add(solver::kErrorInfoTypeUrl, info);
  }
  if (code == grpc::StatusCode::INVALID_ARGUMENT || code == grpc::StatusCode::OUT_OF_RANGE) {
    if (const std::string field = OffendingField(status.message()); !field.empty()) {
      inbetween::v1::BadRequest bad;
      inbetween::v1::BadRequest::FieldViolation* violation = bad.add_field_violations();
      violation->set_field(field);
      violation->set_description(std::string(status.message()));
      add(solver::kBadRequestTypeUrl, bad);
    }
  }
  if (const int64_t retry_ms = solver::RetryAfterMs(status); retry_ms > 0) {
    inbetween::v1::RetryInfo retry;
    retry.mutable_retry_delay()->set_seconds(retry_ms / 1000);
    retry.mutable_retry_delay()->set_nanos(static_cast<int32_t>(retry_ms % 1000 * 1'000'000));
    add(solver::kRetryInfoTypeUrl, retry);
  }
  if (details.details().empty()) return grpc::Status(code, std::string(status.message()));
  details.set_code(static_cast<int32_t>(code));
  details.set_message(std::string(status.message()));
  return grpc::Status(code, std::string(status.message()), details.SerializeAsString());
}

}  // namespace inbetween::server
