// MeshingParameters.corner_matching reaches BuildMultimesh through the service: a sheared,
// rotated copy of a concave arrowhead cannot be mapped with the arc-length correspondence alone
// (NEVER: built only by the overlay), is meshed by default (corners matched on the second attempt)
// and with ALWAYS, and then every corner of the arrowhead sits at its affine image in the copy (the
// build's stats count the corner-matched loop; an ordinary build counts none).
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

// An outline element through the given points (counter-clockwise: positive signed area).
v1::TopologyElement Outline(const std::vector<Pt>& points) {
  v1::TopologyElement element;
  element.set_kind(v1::ELEMENT_KIND_OUTLINE);
  for (Pt p : points) {
    v1::Point* q = element.mutable_polyline()->add_points();
    q->set_x(p.first);
    q->set_y(p.second);
  }
  return element;
}

class CornerMatchingServiceTest : public ServerTest {
 protected:
  // A new session holding one drawing per outline.
  void PutDrawings(const std::vector<v1::TopologyElement>& outlines) {
    session_ = CreateSession("corner matching");
    for (const v1::TopologyElement& outline : outlines) {
      v1::PutDrawingResponse response;
      const grpc::Status status = PutPolylines(session_, outline, &response);
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
    // Corner matching is the fallback of the arc-length correspondence, which this pins (the
    // feature alignment, the default, pairs the arrowhead's corners at the first attempt).
    request.mutable_meshing()->set_boundary_alignment(v1::BOUNDARY_ALIGNMENT_ARC_LENGTH);
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

  v1::Session session_;
};

TEST_F(CornerMatchingServiceTest, TheSettingDecidesWhetherTheAffineCopyIsMeshed) {
  std::vector<Pt> copy;
  for (Pt p : Arrowhead()) copy.push_back(Affine(p));
  ASSERT_NO_FATAL_FAILURE(PutDrawings({Outline(Arrowhead()), Outline(copy)}));
  v1::Multimesh mesh;
  v1::MultimeshStats never_stats;
  // By arc length alone neither drawing's mesh maps into the other: the build overlays one with
  // a triangulation of the other instead (MultimeshOptions::overlay), corners left unmatched.
  const grpc::Status never = Build(v1::CORNER_MATCHING_NEVER, &mesh, &never_stats);
  ASSERT_TRUE(never.ok()) << never.error_code() << ": " << never.error_message();
  EXPECT_EQ(never_stats.overlays(), 1u);
  EXPECT_EQ(never_stats.corner_matched_loops(), 0u);

  for (v1::CornerMatching matching :
       {v1::CORNER_MATCHING_UNSPECIFIED, v1::CORNER_MATCHING_ALWAYS}) {
    SCOPED_TRACE(v1::CornerMatching_Name(matching));
    mesh.Clear();
    v1::MultimeshStats stats;
    const grpc::Status status = Build(matching, &mesh, &stats);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(stats.corner_matched_loops(), 1u);
    EXPECT_EQ(stats.overlays(), 0u);
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
  ASSERT_NO_FATAL_FAILURE(PutDrawings({SquareOutline(0, 0, 1), SquareOutline(0, 0, 2)}));
  v1::Multimesh mesh;
  v1::MultimeshStats stats;
  ASSERT_TRUE(Build(v1::CORNER_MATCHING_UNSPECIFIED, &mesh, &stats).ok());
  EXPECT_EQ(stats.corner_matched_loops(), 0u);
  ASSERT_TRUE(Build(v1::CORNER_MATCHING_ALWAYS, &mesh, &stats).ok());
  EXPECT_EQ(stats.corner_matched_loops(), 1u);
}

}  // namespace
}  // namespace inbetween::server::testing
