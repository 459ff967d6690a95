// The one place where internal errors (absl::Status from the solver and the session store)
// become RPC status. Every absl code maps to the grpc code of the same name.
#pragma once

#include <grpcpp/support/status.h>

#include "absl/status/status.h"

namespace inbetween::server {

grpc::Status ToGrpcStatus(const absl::Status& status);

}  // namespace inbetween::server
