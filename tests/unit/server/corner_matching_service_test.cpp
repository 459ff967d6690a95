// MeshingParameters.corner_matching reaches BuildMultimesh through the service: a sheared,
// rotated copy of a concave arrowhead cannot be meshed with the arc-length correspondence alone
// (NEVER), is meshed by default (corners matched on the second attempt) and with ALWAYS, and then
// every corner of the arrowhead sits at its affine image in the copy (the build's stats count
// the corner-matched loop; an ordinary build counts none).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

using Pt = std::pair<double, double>;

// The arrowhead (counter-clockwise) and its image under rotation by 0.5 rad of a shear.
std::vector<Pt> Arrowhead() { return {{0, 28}, {0, 0}, {30, 9}, {2, 2}}; }
Pt Affine(Pt p) {
  const double c = std::cos(0.5), s = std::sin(0.5), scale = 0.9, shear = -0.5;
  const double x = scale * (p.first + shear * p.second), y = scale * p.second;
  return {c * x - s * y + 5, s * x + c * y - 3};
}

class CornerMatchingServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.shutdown_grace = std::chrono::milliseconds(500);
    absl::StatusOr<std::unique_ptr<InbetweenServer>> server = InbetweenServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = *std::move(server);
    stub_ = v1::Inbetween::NewStub(server_->InProcessChannel());
  }

  // A new session holding one drawing per outline (counter-clockwise points).
  void PutDrawings(const std::vector<std::vector<Pt>>& outlines) {
    grpc::ClientContext context;
    v1::CreateSessionResponse created;
    ASSERT_TRUE(stub_->CreateSession(&context, v1::CreateSessionRequest(), &created).ok());
    session_ = created.session();
    for (const std::vector<Pt>& points : outlines) {
      grpc::ClientContext put_context;
      v1::PutDrawingRequest request;
      request.set_session_id(session_.id());
      request.set_expected_version(session_.version());
      v1::TopologyElement* outline = request.mutable_drawing()->mutable_polylines()->add_elements();
      outline->set_kind(v1::ELEMENT_KIND_OUTLINE);
      for (Pt p : points) {
        v1::Point* q = outline->mutable_polyline()->add_points();
        q->set_x(p.first);
        q->set_y(p.second);
      }
      v1::PutDrawingResponse response;
      const grpc::Status status = stub_->PutDrawing(&put_context, request, &response);
      ASSERT_TRUE(status.ok()) << status.error_message();
      session_ = response.session();
    }
  }

  // Builds with the given corner matching; the result's multimesh (and stats) when it succeeded.
  grpc::Status Build(v1::CornerMatching matching, v1::Multimesh* multimesh,
                     v1::MultimeshStats* stats = nullptr) {
    grpc::ClientContext context;
    v1::BuildMultimeshRequest request;
    request.set_session_id(session_.id());
    request.set_expected_version(session_.version());
    request.mutable_meshing()->set_corner_matching(matching);
    auto reader = stub_->BuildMultimesh(&context, request);
    v1::BuildMultimeshResponse message;
    while (reader->Read(&message)) {
      if (message.has_result()) {
        *multimesh = message.result().multimesh();
        if (stats != nullptr) *stats = message.result().stats();
        session_ = message.result().session();
      }
    }
    return reader->Finish();
  }

  std::unique_ptr<InbetweenServer> server_;
  std::unique_ptr<v1::Inbetween::Stub> stub_;
  v1::Session session_;
};

TEST_F(CornerMatchingServiceTest, TheSettingDecidesWhetherTheAffineCopyIsMeshed) {
  std::vector<Pt> copy;
  for (Pt p : Arrowhead()) copy.push_back(Affine(p));
  ASSERT_NO_FATAL_FAILURE(PutDrawings({Arrowhead(), copy}));
  v1::Multimesh mesh;
  const grpc::Status never = Build(v1::CORNER_MATCHING_NEVER, &mesh);
  EXPECT_FALSE(never.ok());
  EXPECT_TRUE(never.error_code() == grpc::StatusCode::INVALID_ARGUMENT ||
              never.error_code() == grpc::StatusCode::FAILED_PRECONDITION)
      << never.error_code() << ": " << never.error_message();

  for (v1::CornerMatching matching :
       {v1::CORNER_MATCHING_UNSPECIFIED, v1::CORNER_MATCHING_ALWAYS}) {
    SCOPED_TRACE(v1::CornerMatching_Name(matching));
    mesh.Clear();
    v1::MultimeshStats stats;
    const grpc::Status status = Build(matching, &mesh, &stats);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(stats.corner_matched_loops(), 1u);
    ASSERT_EQ(mesh.shapes_size(), 2);
    for (Pt corner : Arrowhead()) {
      int at = -1;
      for (uint32_t v : mesh.boundary()) {
        const v1::Point& p = mesh.shapes(0).vertices(static_cast<int>(v));
        if (std::hypot(p.x() - corner.first, p.y() - corner.second) < 1e-9)
          at = static_cast<int>(v);
      }
      ASSERT_GE(at, 0) << "corner (" << corner.first << ", " << corner.second << ")";
      const v1::Point& q = mesh.shapes(1).vertices(at);
      const Pt image = Affine(corner);
      EXPECT_LT(std::hypot(q.x() - image.first, q.y() - image.second), 1e-9);
    }
  }
}

TEST_F(CornerMatchingServiceTest, ArcLengthBuildsCountNoCornerMatchedLoop) {
  // Two squares: arc length meshes them, so the default build matches no corners; ALWAYS does.
  ASSERT_NO_FATAL_FAILURE(
      PutDrawings({{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{0, 0}, {2, 0}, {2, 2}, {0, 2}}}));
  v1::Multimesh mesh;
  v1::MultimeshStats stats;
  ASSERT_TRUE(Build(v1::CORNER_MATCHING_UNSPECIFIED, &mesh, &stats).ok());
  EXPECT_EQ(stats.corner_matched_loops(), 0u);
  ASSERT_TRUE(Build(v1::CORNER_MATCHING_ALWAYS, &mesh, &stats).ok());
  EXPECT_EQ(stats.corner_matched_loops(), 1u);
}

}  // namespace
}  // namespace inbetween::server::testing
