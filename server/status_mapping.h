// The one place where internal errors (absl::Status from the solver and the session store)
// become RPC status. Every absl code maps to the grpc code of the same name.
#pragma once

#include <grpcpp/support/status.h>

#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace inbetween::server {

// Details (inbetween.proto ErrorStatus): ErrorInfo for a reason payload (solver/core/error_reason.h),
// BadRequest for INVALID_ARGUMENT / OUT_OF_RANGE whose message starts with a request field's path
// (every message names its field first), RetryInfo for a retry-after payload.
grpc::Status ToGrpcStatus(const absl::Status& status);

// The request field path `message` starts with ("drawings[1].svg: ..." -> "drawings[1].svg"),
// checked against the service's request messages; "" when it names no field.
std::string OffendingField(absl::string_view message);

}  // namespace inbetween::server
