// A request whose bytes do not parse as the method's message (truncated or corrupt protobuf)
// never reaches a handler: gRPC answers INTERNAL with an empty message, which our API reserves
// for bugs. This server interceptor rewrites exactly that answer to INVALID_ARGUMENT with a
// message saying what was wrong (docs/bad-input.md, truncated_* cases).
#pragma once

#include <grpcpp/support/server_interceptor.h>

#include <memory>
#include <vector>

namespace inbetween::server {

inline constexpr char kUnparsableRequestMessage[] =
    "the request message could not be parsed (truncated or not a valid protobuf message of the "
    "method's request type)";

// For ServerBuilder::experimental().SetInterceptorCreators.
std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>>
RequestParseErrorInterceptors();

}  // namespace inbetween::server
