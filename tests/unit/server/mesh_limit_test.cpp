// --max-mesh-vertices bounds the mesher itself: a build whose refinement would need more
// vertices stops there with RESOURCE_EXHAUSTED (it does not refine first and count afterwards).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

using ::testing::HasSubstr;

TEST(MeshLimitTest, RefinementStopsAtTheServersVertexLimit) {
  ServerOptions options;
  options.shutdown_grace = std::chrono::milliseconds(500);
  options.service.limits.max_mesh_vertices = 150;
  absl::StatusOr<std::unique_ptr<InbetweenServer>> server = InbetweenServer::Start(options);
  ASSERT_TRUE(server.ok()) << server.status();
  std::unique_ptr<v1::Inbetween::Stub> stub =
      v1::Inbetween::NewStub((*server)->InProcessChannel());

  v1::Session session;
  {
    grpc::ClientContext context;
    v1::CreateSessionResponse created;
    ASSERT_TRUE(stub->CreateSession(&context, v1::CreateSessionRequest(), &created).ok());
    session = created.session();
  }
  for (const char* name : {"square", "hexagon"}) {
    grpc::ClientContext context;
    v1::PutDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.mutable_drawing()->set_svg(
        ReadExample(std::string("examples/square_hexagon/") + name + ".svg"));
    v1::PutDrawingResponse response;
    grpc::Status status = stub->PutDrawing(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    session = response.session();
  }
  // 64 boundary vertices are within the limit, but triangles of 1% of the diagonal need
  // thousands of interior vertices.
  grpc::ClientContext context;
  v1::BuildMultimeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  request.mutable_meshing()->set_boundary_vertices(64);
  request.mutable_meshing()->set_max_edge_relative(0.01);
  auto reader = stub->BuildMultimesh(&context, request);
  v1::BuildMultimeshResponse message;
  while (reader->Read(&message)) {
  }
  const grpc::Status status = reader->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("more than 150 vertices"));
}

}  // namespace
}  // namespace inbetween::server::testing
