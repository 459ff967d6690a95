// A truncated or corrupt request message is INVALID_ARGUMENT with a clear message, not gRPC's
// INTERNAL with an empty one (tests/data/bad/truncated_*.json, garbage_wire_bytes.json).
#include "server/request_parse_errors.h"

#include <gmock/gmock.h>
#include <grpcpp/impl/codegen/client_unary_call.h>
#include <grpcpp/support/byte_buffer.h>
#include <gtest/gtest.h>

#include <string>

#include "inbetween/v1/inbetween.grpc.pb.h"
#include "server/inbetween_server.h"

namespace inbetween::server {
namespace {

namespace v1 = ::inbetween::v1;

grpc::Status CallRaw(grpc::Channel* channel, const std::string& method, const std::string& bytes) {
  grpc::Slice slice(bytes);
  grpc::ByteBuffer request(&slice, 1), response;
  grpc::ClientContext ctx;
  const std::string path = "/inbetween.v1.Inbetween/" + method;
  grpc::internal::RpcMethod rpc(path.c_str(), grpc::internal::RpcMethod::NORMAL_RPC);
  return grpc::internal::BlockingUnaryCall<grpc::ByteBuffer, grpc::ByteBuffer>(channel, rpc, &ctx,
                                                                               request, &response);
}

TEST(RequestParseErrorsTest, TruncatedAndCorruptRequestsAreInvalidArgument) {
  ServerOptions options;
  options.reflection = false;
  absl::StatusOr<std::unique_ptr<InbetweenServer>> server = InbetweenServer::Start(options);
  ASSERT_TRUE(server.ok()) << server.status();
  std::shared_ptr<grpc::Channel> channel = (*server)->InProcessChannel();

  v1::PutDrawingRequest put;
  put.set_session_id("abc");
  put.mutable_drawing()->set_svg("<svg xmlns=\"http://www.w3.org/2000/svg\"/>");
  std::string bytes = put.SerializeAsString();
  bytes.resize(bytes.size() - 5);  // inside the drawing's length-delimited field
  grpc::Status truncated = CallRaw(channel.get(), "PutDrawing", bytes);
  EXPECT_EQ(truncated.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(truncated.error_message(), kUnparsableRequestMessage);

  v1::CreateSessionRequest create;
  create.set_display_name("x");
  grpc::Status corrupt =
      CallRaw(channel.get(), "CreateSession", create.SerializeAsString() + "\x0f");
  EXPECT_EQ(corrupt.error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  // A well-formed request still reaches the handler.
  grpc::Status ok = CallRaw(channel.get(), "CreateSession", create.SerializeAsString());
  EXPECT_TRUE(ok.ok()) << ok.error_message();
  (*server)->Shutdown();
}

}  // namespace
}  // namespace inbetween::server
