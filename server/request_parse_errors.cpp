// Rewrites gRPC's INTERNAL-with-empty-message answer to a request that failed to deserialize
// into INVALID_ARGUMENT (see request_parse_errors.h). Our handlers never return INTERNAL
// without a message (ToGrpcStatus keeps the solver's text), so the condition names only that
// case.
#include "server/request_parse_errors.h"

#include <grpcpp/support/status.h>

namespace inbetween::server {
namespace {

class RequestParseErrorInterceptor final : public grpc::experimental::Interceptor {
 public:
  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(
            grpc::experimental::InterceptionHookPoints::PRE_SEND_STATUS)) {
      const grpc::Status status = methods->GetSendStatus();
      if (status.error_code() == grpc::StatusCode::INTERNAL && status.error_message().empty()) {
        methods->ModifySendStatus(
            grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, kUnparsableRequestMessage));
      }
    }
    methods->Proceed();
  }
};

class RequestParseErrorFactory final
    : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* /*info*/) override {
    return new RequestParseErrorInterceptor();
  }
};

}  // namespace

std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>>
RequestParseErrorInterceptors() {
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> out;
  out.push_back(std::make_unique<RequestParseErrorFactory>());
  return out;
}

}  // namespace inbetween::server
