// The Inbetween service through a real in-process server: sessions, drawings, status codes,
// export/import, the heavy stages and cancellation.
#include "server/inbetween_service.h"

#include <gmock/gmock.h>
#include <grpcpp/client_context.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "absl/strings/str_format.h"
#include "tests/unit/server/many_layers_svg.h"
#include "server/parameters.h"
#include "server/proto_convert.h"
#include "solver/comesh/comesh_topology.h"
#include "solver/core/types.h"
#include "solver/io/svg_import.h"
#include "solver/mesh/validate.h"
#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

using ::testing::HasSubstr;
using ::testing::SizeIs;

// All messages of an Inbetween stream plus its final status.
struct InbetweenRun {
  std::vector<v1::InbetweenResponse> messages;
  grpc::Status status;
};

InbetweenRun RunInbetween(v1::Inbetween::Stub& stub, const v1::InbetweenRequest& request) {
  InbetweenRun run;
  grpc::ClientContext context;
  auto reader = stub.Inbetween(&context, request);
  v1::InbetweenResponse message;
  while (reader->Read(&message)) run.messages.push_back(message);
  run.status = reader->Finish();
  return run;
}

// The header of a 3-frame Inbetween stream of the session (a failed test and an empty header
// when the stream fails).
v1::InbetweenHeader HeaderOfThreeFrames(v1::Inbetween::Stub& stub, const std::string& session_id) {
  v1::InbetweenRequest request;
  request.set_session_id(session_id);
  request.mutable_parameters()->set_frames(3);
  InbetweenRun run = RunInbetween(stub, request);
  EXPECT_TRUE(run.status.ok()) << run.status.error_message();
  if (run.messages.empty() || !run.messages[0].has_header()) {
    ADD_FAILURE() << "the stream has no header";
    return {};
  }
  return run.messages[0].header();
}

struct BuildRun {
  std::vector<v1::Progress> progress;
  v1::BuildMultimeshResult result;
  int results = 0;
  grpc::Status status;
};

BuildRun RunBuild(v1::Inbetween::Stub& stub, const v1::Session& session) {
  BuildRun run;
  grpc::ClientContext context;
  v1::BuildMultimeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  auto reader = stub.BuildMultimesh(&context, request);
  v1::BuildMultimeshResponse message;
  while (reader->Read(&message)) {
    if (message.has_progress()) {
      EXPECT_EQ(run.results, 0) << "progress after the result";
      run.progress.push_back(message.progress());
    } else if (message.has_result()) {
      run.result = message.result();
      ++run.results;
    }
  }
  run.status = reader->Finish();
  return run;
}

solver::Points ToPoints(const google::protobuf::RepeatedPtrField<v1::Point>& points) {
  solver::Points out;
  for (const v1::Point& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

std::vector<solver::Triangle> ToTriangles(
    const google::protobuf::RepeatedPtrField<v1::Triangle>& triangles) {
  std::vector<solver::Triangle> out;
  for (const v1::Triangle& t : triangles) {
    out.push_back({static_cast<int>(t.a()), static_cast<int>(t.b()), static_cast<int>(t.c())});
  }
  return out;
}

// Checks a complete stream: header first, `frames` frames in order, keys hit the shapes exactly
// and no frame has an inverted triangle.
void ExpectValidAnimation(const InbetweenRun& run, const v1::Multimesh& mesh, int frames,
                          int first_frame = 0) {
  ASSERT_TRUE(run.status.ok()) << run.status.error_message();
  ASSERT_THAT(run.messages, SizeIs(frames - first_frame + 1));
  ASSERT_TRUE(run.messages[0].has_header());
  const v1::InbetweenHeader& header = run.messages[0].header();
  EXPECT_EQ(header.frames(), static_cast<uint32_t>(frames));
  ASSERT_EQ(header.keys_size(), mesh.shapes_size());
  EXPECT_EQ(header.keys(0), 0u);
  EXPECT_EQ(header.keys(header.keys_size() - 1), static_cast<uint32_t>(frames - 1));
  const std::vector<solver::Triangle> triangles = ToTriangles(header.triangles());
  EXPECT_EQ(triangles, ToTriangles(mesh.triangles()));
  for (int i = first_frame; i < frames; ++i) {
    const v1::InbetweenResponse& message = run.messages[i - first_frame + 1];
    ASSERT_TRUE(message.has_frame()) << "message " << i - first_frame + 1;
    const v1::InbetweenFrame& frame = message.frame();
    EXPECT_EQ(frame.index(), static_cast<uint32_t>(i));
    EXPECT_EQ(frame.weights_size(), mesh.shapes_size());
    ASSERT_EQ(frame.vertices_size(), mesh.shapes(0).vertices_size());
    EXPECT_EQ(frame.stats().inverted_triangles(), 0u) << "frame " << i;
    EXPECT_EQ(frame.stats().boundary_overlaps(), 0u) << "frame " << i;
    EXPECT_GT(frame.stats().min_area_ratio(), 0.0) << "frame " << i;
    EXPECT_GE(frame.stats().max_area_ratio(), frame.stats().min_area_ratio()) << "frame " << i;
    EXPECT_EQ(solver::CountInverted(triangles, ToPoints(frame.vertices())), 0) << "frame " << i;
  }
  for (int k = 0; k < header.keys_size(); ++k) {
    const int index = static_cast<int>(header.keys(k));
    if (index < first_frame) continue;
    const v1::InbetweenFrame& frame = run.messages[index - first_frame + 1].frame();
    const v1::ShapeGeometry& shape = mesh.shapes(k);
    for (int v = 0; v < frame.vertices_size(); ++v) {
      // Exactly: a key frame is the drawing's own mesh, not an approximation of it.
      EXPECT_EQ(frame.vertices(v).x(), shape.vertices(v).x()) << "key " << k << " vertex " << v;
      EXPECT_EQ(frame.vertices(v).y(), shape.vertices(v).y()) << "key " << k << " vertex " << v;
    }
  }
}

using InbetweenServiceTest = ServerTest;

// ---------------------------------------------------------------------------------------------
// Sessions

TEST_F(InbetweenServiceTest, SessionCrud) {
  v1::Session created = CreateSession("first");
  EXPECT_FALSE(created.id().empty());
  EXPECT_EQ(created.version(), 1u);
  EXPECT_EQ(created.display_name(), "first");
  EXPECT_EQ(created.stage(), v1::STAGE_UNSPECIFIED);

  {
    grpc::ClientContext context;
    v1::GetSessionRequest request;
    request.set_session_id(created.id());
    v1::GetSessionResponse response;
    ASSERT_TRUE(stub_->GetSession(&context, request, &response).ok());
    EXPECT_EQ(response.session().id(), created.id());
    EXPECT_EQ(response.session().display_name(), "first");
  }
  {
    grpc::ClientContext context;
    v1::DeleteSessionRequest request;
    request.set_session_id(created.id());
    request.set_expected_version(1);
    v1::DeleteSessionResponse response;
    ASSERT_TRUE(stub_->DeleteSession(&context, request, &response).ok());
  }
  {
    grpc::ClientContext context;
    v1::GetSessionRequest request;
    request.set_session_id(created.id());
    v1::GetSessionResponse response;
    grpc::Status status = stub_->GetSession(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
    EXPECT_THAT(status.error_message(), HasSubstr(created.id()));
  }
}

TEST_F(InbetweenServiceTest, ListSessionsPages) {
  std::vector<std::string> created;
  for (int i = 0; i < 5; ++i) created.push_back(CreateSession("s" + std::to_string(i)).id());
  std::vector<std::string> listed;
  std::string token;
  int pages = 0;
  do {
    grpc::ClientContext context;
    v1::ListSessionsRequest request;
    request.set_page_size(2);
    request.set_page_token(token);
    v1::ListSessionsResponse response;
    grpc::Status status = stub_->ListSessions(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    for (const v1::Session& s : response.sessions()) {
      listed.push_back(s.id());
      EXPECT_EQ(s.drawings_size(), 0);  // summaries only
    }
    token = response.next_page_token();
    ++pages;
  } while (!token.empty() && pages < 10);
  EXPECT_EQ(listed, created);
  EXPECT_EQ(pages, 3);

  grpc::ClientContext context;
  v1::ListSessionsRequest request;
  request.set_page_token("not-a-token");
  v1::ListSessionsResponse response;
  EXPECT_EQ(stub_->ListSessions(&context, request, &response).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(InbetweenServiceTest, ListSessionsSummariesCountTheDrawings) {
  v1::Session session = CreateSession("two");
  v1::PutDrawingResponse put;
  ASSERT_TRUE(PutPolylines(session, SquareOutline(0, 0, 10), &put).ok());
  ASSERT_TRUE(PutPolylines(put.session(), SquareOutline(0, 0, 20), &put).ok());
  CreateSession("none");
  grpc::ClientContext context;
  v1::ListSessionsResponse response;
  ASSERT_TRUE(stub_->ListSessions(&context, v1::ListSessionsRequest(), &response).ok());
  ASSERT_EQ(response.sessions_size(), 2);
  for (const v1::Session& s : response.sessions()) {
    EXPECT_EQ(s.drawings_size(), 0);
    ASSERT_TRUE(s.has_drawing_count()) << s.display_name();
    EXPECT_EQ(s.drawing_count(), s.display_name() == "two" ? 2u : 0u) << s.display_name();
  }
}

TEST_F(InbetweenServiceTest, StaleExpectedVersionIsAborted) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse put;
  ASSERT_TRUE(PutPolylines(session, SquareOutline(0, 0, 10), &put).ok());
  EXPECT_EQ(put.session().version(), 2u);

  // `session` still says version 1.
  grpc::Status stale = PutPolylines(session, SquareOutline(0, 0, 10), &put);
  EXPECT_EQ(stale.error_code(), grpc::StatusCode::ABORTED);
  EXPECT_EQ(stale.error_message(),
            "session " + session.id() + " is at version 2, request expected 1");

  grpc::ClientContext context;
  v1::DeleteSessionRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(1);
  v1::DeleteSessionResponse response;
  EXPECT_EQ(stub_->DeleteSession(&context, request, &response).error_code(),
            grpc::StatusCode::ABORTED);
  grpc::ClientContext context2;
  request.set_expected_version(0);  // 0 = whatever the version
  EXPECT_TRUE(stub_->DeleteSession(&context2, request, &response).ok());
}

TEST_F(InbetweenServiceTest, UnknownOrMissingSessionId) {
  v1::Session ghost;
  ghost.set_id("0123456789abcdef");
  ghost.set_version(1);
  v1::PutDrawingResponse put;
  EXPECT_EQ(PutPolylines(ghost, SquareOutline(0, 0, 1), &put).error_code(),
            grpc::StatusCode::NOT_FOUND);

  v1::InbetweenRequest request;
  request.set_session_id(ghost.id());
  EXPECT_EQ(RunInbetween(*stub_, request).status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(RunBuild(*stub_, ghost).status.error_code(), grpc::StatusCode::NOT_FOUND);

  grpc::ClientContext context;
  v1::GetSessionRequest get;
  v1::GetSessionResponse response;
  grpc::Status status = stub_->GetSession(&context, get, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("session_id"));
}

// ---------------------------------------------------------------------------------------------
// Drawings

TEST_F(InbetweenServiceTest, BrokenSvgIsInvalidArgumentAndOtherSessionsKeepWorking) {
  v1::Session broken = CreateSession("broken");
  v1::Session healthy = CreateSession("healthy");
  v1::PutDrawingResponse response;
  grpc::Status status = PutSvg(broken, "bad.svg", "<svg><path d='M 0 0 L", &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("drawing.svg"));

  status = PutSvg(broken, "empty.svg", "<svg xmlns='http://www.w3.org/2000/svg'></svg>", &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("drawing.svg"));

  status =
      PutSvg(healthy, "square.svg", ReadExample("examples/square_hexagon/square.svg"), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.session().version(), 2u);
  EXPECT_EQ(response.session().stage(), v1::STAGE_DRAWINGS);
  EXPECT_EQ(response.drawing().id(), 1u);
  ASSERT_EQ(response.drawing().elements_size(), 1);
  EXPECT_EQ(response.drawing().elements(0).kind(), v1::ELEMENT_KIND_OUTLINE);
  EXPECT_EQ(response.drawing().elements(0).id(), 1u);
  EXPECT_GE(response.drawing().elements(0).polyline().points_size(), 4);
  EXPECT_EQ(response.equivalence_class().components(), 1u);
  EXPECT_EQ(response.equivalence_class().holes(), 0u);

  // The failed puts did not touch the broken session.
  grpc::ClientContext context;
  v1::GetSessionRequest get;
  get.set_session_id(broken.id());
  v1::GetSessionResponse got;
  ASSERT_TRUE(stub_->GetSession(&context, get, &got).ok());
  EXPECT_EQ(got.session().version(), 1u);
  EXPECT_EQ(got.session().drawings_size(), 0);
}

TEST_F(InbetweenServiceTest, PolylineDrawingsAreValidated) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse response;

  v1::TopologyElement nan_point = SquareOutline(0, 0, 1);
  nan_point.mutable_polyline()->mutable_points(2)->set_x(std::numeric_limits<double>::infinity());
  grpc::Status status = PutPolylines(session, nan_point, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("drawing.polylines.elements[0] point 2"));

  v1::TopologyElement two_points = SquareOutline(0, 0, 1);
  two_points.mutable_polyline()->mutable_points()->DeleteSubrange(2, 2);
  status = PutPolylines(session, two_points, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("at least 3"));

  v1::TopologyElement bowtie;  // (3,0)-(0,2) crosses (1,2)-(0,0); the area is not zero
  bowtie.set_kind(v1::ELEMENT_KIND_OUTLINE);
  for (auto [x, y] : {std::pair{0.0, 0.0}, {3.0, 0.0}, {0.0, 2.0}, {1.0, 2.0}}) {
    v1::Point* p = bowtie.mutable_polyline()->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  status = PutPolylines(session, bowtie, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("crosses itself"));

  v1::TopologyElement cut = SquareOutline(0, 0, 1);
  cut.set_kind(v1::ELEMENT_KIND_CUT);
  status = PutPolylines(session, cut, &response);  // a cut alone has no outline to cut
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("no outer outline"));

  grpc::ClientContext context;
  v1::PutDrawingRequest no_source;
  no_source.set_session_id(session.id());
  no_source.set_expected_version(session.version());
  status = stub_->PutDrawing(&context, no_source, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("drawing.svg or drawing.polylines"));

  status = PutPolylines(session, SquareOutline(0, 0, 1), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.drawing().elements(0).polyline().points_size(), 4);
}

TEST_F(InbetweenServiceTest, AtMostSixteenDrawings) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse response;
  for (int i = 0; i < kMaxDrawingsPerSession; ++i) {
    ASSERT_TRUE(PutPolylines(session, SquareOutline(i, 0, 1), &response).ok());
    session = response.session();
  }
  grpc::Status status = PutPolylines(session, SquareOutline(0, 0, 1), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("16"));
}

TEST_F(InbetweenServiceTest, ReplaceAndRemoveDrawings) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse put;
  ASSERT_TRUE(PutPolylines(session, SquareOutline(0, 0, 1), &put).ok());
  ASSERT_TRUE(PutPolylines(put.session(), SquareOutline(0, 0, 2), &put).ok());
  session = put.session();
  ASSERT_EQ(session.drawings_size(), 2);
  EXPECT_EQ(session.drawings(1).id(), 2u);

  {  // Replace drawing 1 in place.
    grpc::ClientContext context;
    v1::PutDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.mutable_drawing()->set_id(1);
    *request.mutable_drawing()->mutable_polylines()->add_elements() = SquareOutline(5, 5, 3);
    ASSERT_TRUE(stub_->PutDrawing(&context, request, &put).ok());
    session = put.session();
    EXPECT_EQ(session.drawings(0).id(), 1u);
    EXPECT_EQ(session.drawings(0).elements(0).polyline().points(0).x(), 5.0);
  }
  {  // Unknown drawing id.
    grpc::ClientContext context;
    v1::RemoveDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.set_drawing_id(42);
    v1::RemoveDrawingResponse response;
    EXPECT_EQ(stub_->RemoveDrawing(&context, request, &response).error_code(),
              grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    v1::RemoveDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.set_drawing_id(1);
    v1::RemoveDrawingResponse response;
    ASSERT_TRUE(stub_->RemoveDrawing(&context, request, &response).ok());
    ASSERT_EQ(response.session().drawings_size(), 1);
    EXPECT_EQ(response.session().drawings(0).id(), 2u);
    session = response.session();
  }
  // Ids are not reused.
  ASSERT_TRUE(PutPolylines(session, SquareOutline(0, 0, 1), &put).ok());
  EXPECT_EQ(put.drawing().id(), 3u);
}

TEST_F(InbetweenServiceTest, SetCorrespondences) {
  v1::Session session = ImportTwoSquares();
  ASSERT_EQ(session.stage(), v1::STAGE_MULTIMESH);
  grpc::ClientContext context;
  v1::SetCorrespondencesRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  v1::Correspondence* mark = request.add_correspondences();
  mark->add_points()->set_x(0);
  v1::SetCorrespondencesResponse response;
  grpc::Status status = stub_->SetCorrespondences(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("one per drawing"));

  mark->add_points()->set_x(0);
  grpc::ClientContext context2;
  status = stub_->SetCorrespondences(&context2, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.session().correspondences_size(), 1);
  EXPECT_EQ(response.session().version(), session.version() + 1);
  EXPECT_EQ(response.session().stage(), v1::STAGE_DRAWINGS);  // the multimesh is stale now
}

// ---------------------------------------------------------------------------------------------
// Export / import

// ExportSession's archive of session `id`.
v1::SessionArchive Export(v1::Inbetween::Stub& stub, const std::string& id) {
  grpc::ClientContext context;
  v1::ExportSessionRequest request;
  request.set_session_id(id);
  v1::ExportSessionResponse exported;
  grpc::Status status = stub.ExportSession(&context, request, &exported);
  EXPECT_TRUE(status.ok()) << status.error_message();
  v1::SessionArchive archive;
  EXPECT_TRUE(archive.ParseFromString(exported.data()));
  return archive;
}

grpc::Status Import(v1::Inbetween::Stub& stub, const v1::SessionArchive& archive,
                    v1::ImportSessionResponse* response) {
  grpc::ClientContext context;
  v1::ImportSessionRequest request;
  archive.SerializeToString(request.mutable_data());
  return stub.ImportSession(&context, request, response);
}

TEST_F(InbetweenServiceTest, ExportImportRoundTrip) {
  v1::Session original = ImportTwoSquares();
  grpc::ClientContext context;
  v1::ExportSessionRequest request;
  request.set_session_id(original.id());
  v1::ExportSessionResponse exported;
  ASSERT_TRUE(stub_->ExportSession(&context, request, &exported).ok());
  EXPECT_FALSE(exported.data().empty());

  grpc::ClientContext context2;
  v1::ImportSessionRequest import;
  import.set_data(exported.data());
  import.set_session_id("my-copy");
  v1::ImportSessionResponse imported;
  grpc::Status status = stub_->ImportSession(&context2, import, &imported);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(imported.session().id(), "my-copy");

  auto get_full = [&](const std::string& id) {
    grpc::ClientContext c;
    v1::GetSessionRequest get;
    get.set_session_id(id);
    get.set_full(true);
    v1::GetSessionResponse response;
    EXPECT_TRUE(stub_->GetSession(&c, get, &response).ok());
    return response;
  };
  v1::GetSessionResponse a = get_full(original.id());
  v1::GetSessionResponse b = get_full("my-copy");
  EXPECT_EQ(a.multimesh().SerializeAsString(), b.multimesh().SerializeAsString());
  EXPECT_EQ(b.session().version(), a.session().version());
  EXPECT_EQ(b.session().stage(), v1::STAGE_MULTIMESH);
  a.mutable_session()->clear_id();
  b.mutable_session()->clear_id();
  a.mutable_session()->clear_updated_unix_ms();
  b.mutable_session()->clear_updated_unix_ms();
  EXPECT_EQ(a.session().SerializeAsString(), b.session().SerializeAsString());

  grpc::ClientContext context3;
  EXPECT_EQ(stub_->ImportSession(&context3, import, &imported).error_code(),
            grpc::StatusCode::ALREADY_EXISTS);
}

TEST_F(InbetweenServiceTest, ImportRejectsGarbage) {
  for (const std::string data : {std::string("this is not a protobuf \xff\xff\xff", 26),
                                 std::string(), std::string("\x08\x02", 2)}) {
    grpc::ClientContext context;
    v1::ImportSessionRequest request;
    request.set_data(data);
    v1::ImportSessionResponse response;
    grpc::Status status = stub_->ImportSession(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("data"));
  }
  grpc::ClientContext context;
  v1::ImportSessionRequest request;
  request.set_session_id("bad id with spaces");
  v1::ImportSessionResponse response;
  EXPECT_EQ(stub_->ImportSession(&context, request, &response).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(InbetweenServiceTest, ImportRejectsAnInvertedMultimesh) {
  v1::Session original = ImportTwoSquares();
  v1::SessionArchive archive = Export(*stub_, original.id());
  v1::Triangle* t = archive.mutable_multimesh()->mutable_triangles(0);
  const uint32_t a = t->a();
  t->set_a(t->b());
  t->set_b(a);

  v1::ImportSessionResponse imported;
  grpc::Status status = Import(*stub_, archive, &imported);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("data: multimesh"));
}

// ---------------------------------------------------------------------------------------------
// Art and import report: what PutDrawing stores is exactly what solver::ImportSvg returns for
// the same options, and sessions keep it through every path.

// A face with an eye painted on it (two filled elements that overlap; the eye also stroked).
constexpr char kFaceSvg[] = R"(<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
  <circle id="face" data-layer="face" cx="50" cy="50" r="40" fill="#f0c080"/>
  <circle id="eye" data-layer="eye" cx="35" cy="40" r="6" fill="#203040" stroke="#000000"
          stroke-width="1.5"/>
</svg>)";

v1::PutDrawingRequest FaceRequest(const v1::Session& session, double gap_tolerance = 0,
                                  double min_area_fraction = 0) {
  v1::PutDrawingRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  request.mutable_drawing()->set_name("face");
  request.mutable_drawing()->set_svg(kFaceSvg);
  request.set_gap_tolerance(gap_tolerance);
  request.set_min_area_fraction(min_area_fraction);
  return request;
}

// The report's fields one by one against what ImportSvg said.
void ExpectReportOf(const v1::ImportReport& got, const solver::SvgImportInfo& info,
                    size_t art_layers) {
  const v1::SilhouetteSource sources[] = {v1::SILHOUETTE_SOURCE_ELEMENTS,
                                          v1::SILHOUETTE_SOURCE_UNION,
                                          v1::SILHOUETTE_SOURCE_OUTLINE_CLASS};
  EXPECT_EQ(got.silhouette_source(), sources[static_cast<int>(info.source)]);
  EXPECT_EQ(got.gaps_closed(), static_cast<uint32_t>(info.cleaning.gaps_closed));
  EXPECT_EQ(got.slits_closed(), static_cast<uint32_t>(info.cleaning.slits_closed));
  EXPECT_EQ(got.islands_dropped(), static_cast<uint32_t>(info.cleaning.islands_dropped));
  EXPECT_EQ(got.holes_dropped(), static_cast<uint32_t>(info.cleaning.holes_dropped));
  EXPECT_EQ(got.gap_width(), info.cleaning.gap_width);
  EXPECT_EQ(got.min_area(), info.cleaning.min_area);
  EXPECT_EQ(std::vector<std::string>(got.warnings().begin(), got.warnings().end()), info.warnings);
  EXPECT_EQ(got.art_layers(), art_layers);
}

// A drawing's art, serialized (equal bytes = equal art).
std::string ArtBytes(const v1::Drawing& drawing) {
  v1::Drawing art;
  *art.mutable_art() = drawing.art();
  return art.SerializeAsString();
}

v1::GetSessionResponse GetFull(v1::Inbetween::Stub& stub, const std::string& id, bool full = true) {
  grpc::ClientContext context;
  v1::GetSessionRequest request;
  request.set_session_id(id);
  request.set_full(full);
  v1::GetSessionResponse response;
  grpc::Status status = stub.GetSession(&context, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return response;
}

TEST_F(InbetweenServiceTest, PutDrawingStoresTheArtAndReportOfImportSvg) {
  // Request values -> ImportSvg's: 0 = the default, negative = off.
  const solver::SvgImportOptions defaults;
  struct Case {
    double gap_tolerance, min_area_fraction;  // in the request
    double import_gap, import_min_area;       // what ImportSvg gets
  };
  for (const Case& c : {Case{0, 0, defaults.gap_tolerance, defaults.min_area_fraction},
                        Case{0.01, -1, 0.01, 0}, Case{-0.5, 0.05, 0, 0.05}}) {
    SCOPED_TRACE(::testing::Message()
                 << "gap " << c.gap_tolerance << " min area " << c.min_area_fraction);
    solver::SvgImportOptions options;
    options.gap_tolerance = c.import_gap;
    options.min_area_fraction = c.import_min_area;
    solver::SvgImportInfo info;
    absl::StatusOr<solver::Drawing> expected = solver::ImportSvg(kFaceSvg, options, &info);
    ASSERT_TRUE(expected.ok()) << expected.status();

    const v1::Session session = CreateSession();
    grpc::ClientContext context;
    v1::PutDrawingResponse response;
    grpc::Status status = stub_->PutDrawing(
        &context, FaceRequest(session, c.gap_tolerance, c.min_area_fraction), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    const v1::Drawing& drawing = response.drawing();
    ASSERT_EQ(drawing.art_size(), static_cast<int>(expected->art.size()));
    ExpectSameArt(FromProto(drawing.art()), expected->art);
    ExpectReportOf(drawing.import_report(), info, expected->art.size());
    EXPECT_EQ(response.import_report().SerializeAsString(),
              drawing.import_report().SerializeAsString());

    // Stored with the session: the full session has it, the compact one only the report.
    const v1::Drawing stored = GetFull(*stub_, session.id()).session().drawings(0);
    EXPECT_EQ(stored.art_size(), drawing.art_size());
    ExpectSameArt(FromProto(stored.art()), expected->art);
    const v1::Drawing compact = GetFull(*stub_, session.id(), false).session().drawings(0);
    EXPECT_EQ(compact.art_size(), 0);
    EXPECT_EQ(compact.import_report().SerializeAsString(),
              drawing.import_report().SerializeAsString());
    EXPECT_EQ(response.session().drawings(0).art_size(), 0);  // replies carry the compact session
  }
}

TEST_F(InbetweenServiceTest, ImportOptionsOutOfRangeAreInvalidArgumentNamingTheField) {
  const v1::Session session = CreateSession();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (auto [gap, min_area, field] : {std::tuple{0.5, 0.0, "gap_tolerance"},
                                      {nan, 0.0, "gap_tolerance"},
                                      {-inf, 0.0, "gap_tolerance"},
                                      {0.0, 0.2, "min_area_fraction"},
                                      {0.0, inf, "min_area_fraction"},
                                      {0.0, nan, "min_area_fraction"}}) {
    grpc::ClientContext context;
    v1::PutDrawingResponse response;
    grpc::Status status =
        stub_->PutDrawing(&context, FaceRequest(session, gap, min_area), &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << field;
    EXPECT_THAT(status.error_message(), HasSubstr(std::string(field) + " = ")) << field;
  }
  EXPECT_EQ(GetFull(*stub_, session.id()).session().drawings_size(), 0);
}

TEST_F(InbetweenServiceTest, PolylineDrawingsHaveNoArtAndReportElements) {
  const v1::Session session = CreateSession();
  grpc::ClientContext context;
  v1::PutDrawingRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  *request.mutable_drawing()->mutable_polylines()->add_elements() = SquareOutline(0, 0, 10);
  ToProto(SampleArt(), request.mutable_drawing()->mutable_art());  // output only: ignored
  request.mutable_drawing()->mutable_import_report()->set_art_layers(2);
  v1::PutDrawingResponse response;
  grpc::Status status = stub_->PutDrawing(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.drawing().art_size(), 0);
  v1::ImportReport want;
  want.set_silhouette_source(v1::SILHOUETTE_SOURCE_ELEMENTS);
  EXPECT_EQ(response.drawing().import_report().SerializeAsString(), want.SerializeAsString());
  EXPECT_EQ(response.import_report().SerializeAsString(), want.SerializeAsString());
  EXPECT_EQ(GetFull(*stub_, session.id()).session().drawings(0).art_size(), 0);
}

TEST_F(InbetweenServiceTest, ArtSurvivesExportImportAndTopologyEdits) {
  v1::Session session = CreateSession();
  grpc::ClientContext put_context;
  v1::PutDrawingResponse put;
  ASSERT_TRUE(stub_->PutDrawing(&put_context, FaceRequest(session, 0.01), &put).ok());
  session = put.session();
  const v1::Drawing original = GetFull(*stub_, session.id()).session().drawings(0);
  EXPECT_EQ(ArtBytes(original), ArtBytes(put.drawing()));

  // An edit re-analyses the drawing from its elements: the art and report stay as they were.
  {
    grpc::ClientContext context;
    auto stream = stub_->EditTopology(&context);
    v1::TopologyEdit edit;
    edit.set_session_id(session.id());
    edit.set_expected_version(session.version());
    edit.set_drawing_id(original.id());
    *edit.mutable_move() = original.elements(0);  // moved onto itself
    ASSERT_TRUE(stream->Write(edit));
    v1::TopologyState state;
    ASSERT_TRUE(stream->Read(&state));
    stream->WritesDone();
    ASSERT_TRUE(stream->Finish().ok());
  }
  v1::Drawing edited = GetFull(*stub_, session.id()).session().drawings(0);
  EXPECT_EQ(ArtBytes(edited), ArtBytes(original));
  EXPECT_EQ(edited.import_report().SerializeAsString(),
            original.import_report().SerializeAsString());

  v1::ImportSessionResponse imported;
  grpc::Status status = Import(*stub_, Export(*stub_, session.id()), &imported);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const v1::Drawing copy = GetFull(*stub_, imported.session().id()).session().drawings(0);
  EXPECT_EQ(copy.art_size(), original.art_size());
  EXPECT_EQ(ArtBytes(copy), ArtBytes(original));
  EXPECT_EQ(copy.import_report().SerializeAsString(), original.import_report().SerializeAsString());
}

TEST_F(InbetweenServiceTest, ImportSessionReimportsADrawingWithoutElementsOnce) {
  // An archive whose drawing has its SVG but no elements is imported again (default options):
  // the archive's stale art is replaced, not added to.
  v1::SessionArchive archive;
  archive.set_format_version(1);
  v1::Drawing* drawing = archive.mutable_session()->add_drawings();
  drawing->set_id(1);
  drawing->set_svg(kFaceSvg);
  ToProto(SampleArt(), drawing->mutable_art());
  drawing->mutable_import_report()->set_gaps_closed(42);
  v1::ImportSessionResponse response;
  grpc::Status status = Import(*stub_, archive, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();

  solver::SvgImportInfo info;
  absl::StatusOr<solver::Drawing> expected = solver::ImportSvg(kFaceSvg, {}, &info);
  ASSERT_TRUE(expected.ok()) << expected.status();
  const v1::Drawing stored = GetFull(*stub_, response.session().id()).session().drawings(0);
  EXPECT_GT(stored.elements_size(), 0);
  ExpectSameArt(FromProto(stored.art()), expected->art);
  ExpectReportOf(stored.import_report(), info, expected->art.size());
}

TEST_F(InbetweenServiceTest, ImportSessionRefusesBadArt) {
  const v1::Session original = ImportTwoSquares();
  v1::SessionArchive archive = Export(*stub_, original.id());
  v1::Drawing* drawing = archive.mutable_session()->mutable_drawings(1);
  ToProto(SampleArt(), drawing->mutable_art());
  drawing->mutable_art(1)->mutable_paths(0)->mutable_points(0)->set_x(
      std::numeric_limits<double>::infinity());

  v1::ImportSessionResponse imported;
  grpc::Status status = Import(*stub_, archive, &imported);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("data: session.drawings[1].art[1].paths[0]"));
}

// ---------------------------------------------------------------------------------------------
// The Inbetween header's art: each key's art embedded in the multimesh (InbetweenHeader.art)

// A yellow face with two black eyes and a black stroked mouth, moved by (dx, dy) and scaled by s
// about the origin.
std::string LayeredFaceSvg(double dx, double dy, double s) {
  return absl::StrFormat(
      R"svg(<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 120 120">
  <g transform="translate(%g %g) scale(%g)">
    <circle id="face" cx="50" cy="50" r="40" fill="#ffd020"/>
    <circle id="left-eye" cx="35" cy="40" r="5" fill="#000000"/>
    <circle id="right-eye" cx="65" cy="40" r="5" fill="#000000"/>
    <path id="mouth" d="M 30 62 Q 50 80 70 62" fill="none" stroke="#000000" stroke-width="3"/>
  </g>
</svg>)svg",
      dx, dy, s);
}

// Point i of a packed path in geometry `vertices`: sum_j b_j v[corner_j].
solver::Point PlaceArtPoint(const v1::EmbeddedArtPath& path, int i,
                            const std::vector<solver::Triangle>& triangles,
                            const solver::Points& vertices) {
  const solver::Triangle& t = triangles[path.triangles(i)];
  solver::Point p(0, 0);
  for (int c = 0; c < 3; ++c) p += path.barycentric(3 * i + c) * vertices[t[c]];
  return p;
}

// `placed` is `drawn` with points inserted on its segments: the drawn points in order (within
// `tol`), every other point on the drawn segment it sits between.
void ExpectDrawnWithInsertions(const solver::Points& placed, const solver::Points& drawn,
                               bool closed, double tol) {
  const auto on_segment = [tol](const solver::Point& p, const solver::Point& a,
                                const solver::Point& b) {
    const solver::Point d = b - a;
    const double t =
        d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    return (a + t * d - p).norm() <= tol;
  };
  const int n = static_cast<int>(drawn.size());
  int next = 0;  // the next drawn point to meet
  for (size_t i = 0; i < placed.size(); ++i) {
    if (next < n && (placed[i] - drawn[next]).norm() <= tol) {
      ++next;
      continue;
    }
    ASSERT_GT(next, 0) << "point " << i << " before the first drawn point";
    ASSERT_TRUE(next < n || closed) << "point " << i << " after the last drawn point";
    EXPECT_TRUE(on_segment(placed[i], drawn[next - 1], drawn[next % n]))
        << "point " << i << " (" << placed[i].transpose() << ") off the drawn segment";
  }
  EXPECT_EQ(next, n) << "drawn points met";
}

TEST_F(InbetweenServiceTest, InbetweenHeaderCarriesEachKeysArtInMeshCoordinates) {
  v1::Session session = CreateSession("faces");
  for (const std::string& svg : {LayeredFaceSvg(0, 0, 1), LayeredFaceSvg(12, 6, 0.85)}) {
    v1::PutDrawingResponse put;
    grpc::Status status = PutSvg(session, "face", svg, &put);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_EQ(put.drawing().art_size(), 4);
    session = put.session();
  }
  BuildRun build = RunBuild(*stub_, session);
  ASSERT_TRUE(build.status.ok()) << build.status.error_message();
  const v1::Multimesh& mesh = build.result.multimesh();
  const v1::Session full = GetFull(*stub_, session.id()).session();

  const v1::InbetweenHeader header = HeaderOfThreeFrames(*stub_, session.id());
  const std::vector<solver::Triangle> triangles = ToTriangles(header.triangles());
  ASSERT_EQ(header.art_size(), 2);
  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE(::testing::Message() << "key " << k);
    const v1::KeyArt& art = header.art(k);
    EXPECT_EQ(art.key(), static_cast<uint32_t>(k));
    const v1::Drawing& drawing = full.drawings(k);
    ASSERT_EQ(art.layers_size(), drawing.art_size());
    const solver::Points vertices = ToPoints(mesh.shapes(k).vertices());
    for (int l = 0; l < art.layers_size(); ++l) {
      SCOPED_TRACE(::testing::Message() << "layer " << l);
      const v1::EmbeddedArtLayer& layer = art.layers(l);
      // Paint as drawn, without the drawn paths.
      v1::ArtLayer paint = drawing.art(l);
      paint.clear_paths();
      EXPECT_EQ(layer.paint().SerializeAsString(), paint.SerializeAsString());
      ASSERT_EQ(layer.paths_size(), drawing.art(l).paths_size());
      for (int p = 0; p < layer.paths_size(); ++p) {
        const v1::EmbeddedArtPath& path = layer.paths(p);
        ASSERT_EQ(path.barycentric_size(), 3 * path.triangles_size());
        EXPECT_EQ(path.closed(), drawing.art(l).paths(p).closed());
        solver::Points placed;
        for (int i = 0; i < path.triangles_size(); ++i) {
          ASSERT_LT(path.triangles(i), triangles.size());
          placed.push_back(PlaceArtPoint(path, i, triangles, vertices));
        }
        ExpectDrawnWithInsertions(placed, ToPoints(drawing.art(l).paths(p).points()), path.closed(),
                                  1e-6);
      }
    }
  }
  // The header's art is the stored multimesh's, embedded once by BuildMultimesh.
  EXPECT_EQ(header.art_messages(), 0u);
  ASSERT_EQ(mesh.art_size(), 2);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(mesh.art(k).SerializeAsString(), header.art(k).SerializeAsString()) << "key " << k;
  }
  // The layers' paint: yellow face, black eyes, a black stroke without fill.
  const v1::KeyArt& first = header.art(0);
  EXPECT_EQ(first.layers(0).paint().fill().rgb(), 0xffd020u);
  EXPECT_EQ(first.layers(1).paint().fill().rgb(), 0x000000u);
  EXPECT_EQ(first.layers(2).paint().id(), "right-eye");
  EXPECT_FALSE(first.layers(3).paint().has_fill());
  EXPECT_EQ(first.layers(3).paint().stroke().width(), 3.0);
  EXPECT_FALSE(first.layers(3).paths(0).closed());
}

// Every art point of `mesh`'s art is in one of its triangles, and key k's art placed in shape k
// is drawing k's art (drawn points in order, crossings on the drawn segments).
void ExpectArtOfDrawings(const v1::Multimesh& mesh, const v1::Session& full) {
  const std::vector<solver::Triangle> triangles = ToTriangles(mesh.triangles());
  ASSERT_EQ(mesh.art_size(), full.drawings_size());
  for (int k = 0; k < mesh.art_size(); ++k) {
    const v1::KeyArt& art = mesh.art(k);
    ASSERT_EQ(art.layers_size(), full.drawings(k).art_size());
    const solver::Points vertices = ToPoints(mesh.shapes(k).vertices());
    for (int l = 0; l < art.layers_size(); ++l) {
      for (int p = 0; p < art.layers(l).paths_size(); ++p) {
        const v1::EmbeddedArtPath& path = art.layers(l).paths(p);
        solver::Points placed;
        for (int i = 0; i < path.triangles_size(); ++i) {
          ASSERT_LT(path.triangles(i), triangles.size());
          placed.push_back(PlaceArtPoint(path, i, triangles, vertices));
        }
        ExpectDrawnWithInsertions(placed, ToPoints(full.drawings(k).art(l).paths(p).points()),
                                  path.closed(), 1e-6);
      }
    }
  }
}

TEST_F(InbetweenServiceTest, OptimizeEmbedsTheArtAgainAndExportsKeepIt) {
  v1::Session session = CreateSession("faces");
  for (const std::string& svg : {LayeredFaceSvg(0, 0, 1), LayeredFaceSvg(12, 6, 0.85)}) {
    v1::PutDrawingResponse put;
    ASSERT_TRUE(PutSvg(session, "face", svg, &put).ok());
    session = put.session();
  }
  BuildRun build = RunBuild(*stub_, session);
  ASSERT_TRUE(build.status.ok()) << build.status.error_message();
  const v1::Session full = GetFull(*stub_, session.id()).session();

  grpc::ClientContext context;
  v1::OptimizeComeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(build.result.session().version());
  request.mutable_comesh()->set_max_outer_iterations(2);
  auto reader = stub_->OptimizeComesh(&context, request);
  v1::OptimizeComeshResponse message;
  v1::OptimizeComeshResult optimized;
  while (reader->Read(&message)) {
    if (message.has_result()) optimized = message.result();
  }
  grpc::Status status = reader->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  // The optimizer changes the triangles; the art rides the new ones.
  ASSERT_NE(optimized.multimesh().triangles_size(), 0);
  ExpectArtOfDrawings(optimized.multimesh(), full);
  const v1::InbetweenHeader header = HeaderOfThreeFrames(*stub_, session.id());
  ASSERT_EQ(header.art_size(), 2);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(header.art(k).SerializeAsString(), optimized.multimesh().art(k).SerializeAsString());
  }

  // Exported with the multimesh; an import embeds it again from the drawings, to the same art,
  // and an archive without it (written before the multimesh carried art) gets it back.
  v1::SessionArchive archive = Export(*stub_, session.id());
  ASSERT_EQ(archive.multimesh().art_size(), 2);
  archive.mutable_multimesh()->clear_art();
  v1::ImportSessionResponse imported;
  ASSERT_TRUE(Import(*stub_, archive, &imported).ok());
  const v1::GetSessionResponse copy = GetFull(*stub_, imported.session().id());
  ASSERT_EQ(copy.multimesh().art_size(), 2);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(copy.multimesh().art(k).SerializeAsString(),
              optimized.multimesh().art(k).SerializeAsString());
  }
}

TEST_F(InbetweenServiceTest, LargeArtFollowsTheHeaderInMessagesUnderOneMebibyte) {
  v1::Session session = CreateSession("many layers");
  for (double dx : {0.0, 6.0}) {
    v1::PutDrawingResponse put;
    grpc::Status status = PutSvg(session, "grid", ManyLayersSvg(2000, dx), &put);
    ASSERT_TRUE(status.ok()) << status.error_message();
    session = put.session();
  }
  BuildRun build = RunBuild(*stub_, session);
  ASSERT_TRUE(build.status.ok()) << build.status.error_message();
  const v1::Multimesh& mesh = build.result.multimesh();
  ASSERT_EQ(mesh.art_size(), 2);
  ASSERT_EQ(mesh.art(0).layers_size(), 2001);
  ASSERT_GT(mesh.art(0).ByteSizeLong() + mesh.art(1).ByteSizeLong(), size_t{4} << 20)
      << "the art must be larger than gRPC's default receive limit for this test to mean much";

  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(3);
  InbetweenRun run = RunInbetween(*stub_, request);
  ASSERT_TRUE(run.status.ok()) << run.status.error_message();
  ASSERT_FALSE(run.messages.empty());
  ASSERT_TRUE(run.messages[0].has_header());
  v1::InbetweenHeader header = run.messages[0].header();
  const uint32_t chunks = header.art_messages();
  ASSERT_GT(chunks, 0u);
  ASSERT_GT(run.messages.size(), chunks + 3);
  for (const v1::InbetweenResponse& m : run.messages) {
    EXPECT_LE(m.ByteSizeLong(), size_t{1} << 20);
  }
  // The art messages come right after the header; appended, they give the stored art.
  for (uint32_t i = 1; i <= chunks; ++i) {
    ASSERT_TRUE(run.messages[i].has_art()) << "message " << i;
    const v1::KeyArt& more = run.messages[i].art();
    ASSERT_LT(more.key(), 2u);
    EXPECT_GT(more.layers_size(), 0);
    for (const v1::EmbeddedArtLayer& layer : more.layers()) {
      *header.mutable_art(static_cast<int>(more.key()))->add_layers() = layer;
    }
  }
  EXPECT_TRUE(run.messages[chunks + 1].has_frame());
  ASSERT_EQ(header.art_size(), 2);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(header.art(k).SerializeAsString(), mesh.art(k).SerializeAsString()) << "key " << k;
  }
}

TEST_F(InbetweenServiceTest, InbetweenHeaderHasNoArtForPolylineDrawings) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse put;
  ASSERT_TRUE(PutPolylines(session, SquareOutline(0, 0, 1), &put).ok());
  ASSERT_TRUE(PutPolylines(put.session(), SquareOutline(0, 0, 2), &put).ok());
  BuildRun build = RunBuild(*stub_, put.session());
  ASSERT_TRUE(build.status.ok()) << build.status.error_message();
  EXPECT_EQ(HeaderOfThreeFrames(*stub_, session.id()).art_size(), 0);
}

// ---------------------------------------------------------------------------------------------
// Heavy stages

TEST_F(InbetweenServiceTest, BuildMultimeshNeedsTwoDrawings) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse put;
  ASSERT_TRUE(PutPolylines(session, SquareOutline(0, 0, 1), &put).ok());
  BuildRun run = RunBuild(*stub_, put.session());
  EXPECT_EQ(run.status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(run.status.error_message(), HasSubstr("at least 2 drawings"));
}

TEST_F(InbetweenServiceTest, InbetweenBeforeBuildIsFailedPrecondition) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse put;
  ASSERT_TRUE(PutPolylines(session, SquareOutline(0, 0, 1), &put).ok());
  ASSERT_TRUE(PutPolylines(put.session(), SquareOutline(0, 0, 2), &put).ok());
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  InbetweenRun run = RunInbetween(*stub_, request);
  EXPECT_EQ(run.status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(run.status.error_message(), HasSubstr("build the multimesh first"));
  EXPECT_TRUE(run.messages.empty());
}

TEST_F(InbetweenServiceTest, InbetweenFrameLimits) {
  v1::Session session = ImportTwoSquares();
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(1);
  EXPECT_EQ(RunInbetween(*stub_, request).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  request.mutable_parameters()->set_frames(kMaxFrames + 1);
  EXPECT_EQ(RunInbetween(*stub_, request).status.error_code(),
            grpc::StatusCode::RESOURCE_EXHAUSTED);
  request.mutable_parameters()->set_frames(5);
  request.set_start_frame(5);
  EXPECT_EQ(RunInbetween(*stub_, request).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(InbetweenServiceTest, InbetweenOnImportedMultimesh) {
  v1::Session session = ImportTwoSquares();
  grpc::ClientContext context;
  v1::GetSessionRequest get;
  get.set_session_id(session.id());
  get.set_full(true);
  v1::GetSessionResponse full;
  ASSERT_TRUE(stub_->GetSession(&context, get, &full).ok());

  for (v1::Method method : {v1::METHOD_ZHU17, v1::METHOD_LINEAR, v1::METHOD_ALEXA}) {
    SCOPED_TRACE(v1::Method_Name(method));
    v1::InbetweenRequest request;
    request.set_session_id(session.id());
    request.mutable_parameters()->set_frames(7);
    request.mutable_parameters()->set_method(method);
    InbetweenRun run = RunInbetween(*stub_, request);
    ExpectValidAnimation(run, full.multimesh(), 7);
    EXPECT_EQ(run.messages[0].header().session_version(), session.version());
  }
  // Default frame count is 24.
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  ExpectValidAnimation(RunInbetween(*stub_, request), full.multimesh(), 24);
}

TEST_F(InbetweenServiceTest, InbetweenWithStiffnessRegions) {
  v1::Session session = ImportTwoSquares();
  grpc::ClientContext context;
  v1::GetSessionRequest get;
  get.set_session_id(session.id());
  get.set_full(true);
  v1::GetSessionResponse full;
  ASSERT_TRUE(stub_->GetSession(&context, get, &full).ok());
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(5);
  v1::StiffnessRegion* region = request.mutable_parameters()->add_stiffness();
  *region->mutable_polygon() = SquareOutline(-1, -1, 1.6).polyline();  // holds one centroid
  region->set_kappa(50);
  ExpectValidAnimation(RunInbetween(*stub_, request), full.multimesh(), 5);

  region->set_kappa(0);  // out of range
  EXPECT_EQ(RunInbetween(*stub_, request).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(InbetweenServiceTest, InbetweenTimingCurvesAndKeyTimes) {
  v1::Session session = ImportTwoSquares();
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(9);
  InbetweenRun linear = RunInbetween(*stub_, request);
  ASSERT_TRUE(linear.status.ok()) << linear.status.error_message();
  request.mutable_parameters()->set_timing(v1::TIMING_CURVE_EASE_IN_OUT);
  InbetweenRun eased = RunInbetween(*stub_, request);
  ASSERT_TRUE(eased.status.ok()) << eased.status.error_message();
  ASSERT_EQ(eased.messages.size(), linear.messages.size());
  // messages[0] is the header; frame f is messages[f + 1]. Keys stay exact, the ease-in-out
  // frames start slower and end faster than linear ones and meet them in the middle.
  auto weight2 = [](const InbetweenRun& run, int f) {
    return run.messages[f + 1].frame().weights(1);
  };
  EXPECT_EQ(weight2(eased, 0), 0.0);
  EXPECT_EQ(weight2(eased, 8), 1.0);
  EXPECT_DOUBLE_EQ(weight2(linear, 1), 1.0 / 8);
  EXPECT_LT(weight2(eased, 1), weight2(linear, 1));
  EXPECT_GT(weight2(eased, 7), weight2(linear, 7));
  EXPECT_NEAR(weight2(eased, 4), 0.5, 1e-12);

  request.mutable_parameters()->add_ease(0.0);  // no easing at all = linear
  InbetweenRun none = RunInbetween(*stub_, request);
  ASSERT_TRUE(none.status.ok()) << none.status.error_message();
  EXPECT_NEAR(weight2(none, 1), 1.0 / 8, 1e-12);

  request.mutable_parameters()->add_ease(0.5);  // two values for one segment
  InbetweenRun wrong = RunInbetween(*stub_, request);
  EXPECT_EQ(wrong.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(wrong.status.error_message(), HasSubstr("parameters.ease"));

  request.mutable_parameters()->clear_ease();
  request.mutable_parameters()->add_key_times(0.0);
  request.mutable_parameters()->add_key_times(0.5);  // the last key must be at 1
  wrong = RunInbetween(*stub_, request);
  EXPECT_EQ(wrong.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(wrong.status.error_message(), HasSubstr("parameters.key_times"));
}

TEST_F(InbetweenServiceTest, InbetweenResumesAtStartFrame) {
  v1::Session session = ImportTwoSquares();
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(9);
  InbetweenRun all = RunInbetween(*stub_, request);
  ASSERT_TRUE(all.status.ok()) << all.status.error_message();
  request.set_start_frame(4);
  InbetweenRun resumed = RunInbetween(*stub_, request);
  ASSERT_TRUE(resumed.status.ok()) << resumed.status.error_message();
  ASSERT_EQ(resumed.messages.size(), 1u + 5u);
  for (int i = 4; i < 9; ++i) {
    const v1::InbetweenFrame& a = all.messages[i + 1].frame();
    const v1::InbetweenFrame& b = resumed.messages[i - 4 + 1].frame();
    EXPECT_EQ(b.index(), static_cast<uint32_t>(i));
    for (int v = 0; v < a.vertices_size(); ++v) {
      EXPECT_EQ(a.vertices(v).x(), b.vertices(v).x());
      EXPECT_EQ(a.vertices(v).y(), b.vertices(v).y());
    }
  }
}

TEST_F(InbetweenServiceTest, KeyTimeOutOfRangeIsInvalidArgument) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse put;
  ASSERT_TRUE(PutPolylines(session, SquareOutline(0, 0, 1), &put).ok());
  grpc::ClientContext context;
  v1::PutDrawingRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(put.session().version());
  request.mutable_drawing()->set_key_time(2.0);
  *request.mutable_drawing()->mutable_polylines()->add_elements() = SquareOutline(0, 0, 2);
  grpc::Status status = stub_->PutDrawing(&context, request, &put);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("drawing.key_time"));
}

TEST_F(InbetweenServiceTest, KeyTimesComeFromTheDrawingsWhenAllAreSet) {
  v1::InbetweenRequest request;
  request.mutable_parameters()->set_frames(6);
  request.set_session_id(ImportTwoSquares(2.0, {0.0, 1.0}).id());
  InbetweenRun run = RunInbetween(*stub_, request);
  ASSERT_TRUE(run.status.ok()) << run.status.error_message();
  EXPECT_EQ(run.messages[0].header().keys(1), 5u);

  request.set_session_id(ImportTwoSquares(2.0, {0.0, -1.0}).id());
  run = RunInbetween(*stub_, request);
  EXPECT_EQ(run.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(run.status.error_message(), HasSubstr("key_time is set on 1 of 2 drawings"));

  request.set_session_id(ImportTwoSquares(2.0, {0.0, 0.5}).id());  // the last must be 1
  run = RunInbetween(*stub_, request);
  EXPECT_EQ(run.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(run.status.error_message(), HasSubstr("key_time"));
}

TEST_F(InbetweenServiceTest, FullFlowOnTheSquareHexagonExample) {
  v1::Session session = SessionWithExamples();
  ASSERT_EQ(session.drawings_size(), 2);
  BuildRun build = RunBuild(*stub_, session);
  ASSERT_TRUE(build.status.ok()) << build.status.error_message();
  ASSERT_EQ(build.results, 1);
  const v1::BuildMultimeshResult& result = build.result;
  EXPECT_EQ(result.session().version(), session.version() + 1);
  EXPECT_EQ(result.session().stage(), v1::STAGE_MULTIMESH);
  EXPECT_EQ(result.stats().shapes(), 2u);
  EXPECT_GT(result.stats().vertices(), 3u);
  EXPECT_EQ(result.stats().triangles(), static_cast<uint32_t>(result.multimesh().triangles_size()));
  EXPECT_EQ(result.stats().inverted_triangles(), 0u);
  // The worst quality over both drawings, from the multimesh itself.
  double worst = 1.0;
  for (const v1::ShapeGeometry& shape : result.multimesh().shapes()) {
    for (const v1::Triangle& t : result.multimesh().triangles()) {
      const auto p = [&](uint32_t v) {
        return solver::Point(shape.vertices(v).x(), shape.vertices(v).y());
      };
      worst = std::min(worst, solver::TriangleQuality(p(t.a()), p(t.b()), p(t.c())));
    }
  }
  EXPECT_GT(worst, 0.0);
  EXPECT_DOUBLE_EQ(result.stats().worst_quality(), worst);
  EXPECT_EQ(result.session().multimesh_stats().vertices(), result.stats().vertices());
  EXPECT_FALSE(build.progress.empty());
  for (const v1::Progress& p : build.progress) {
    EXPECT_GE(p.fraction(), 0.0);
    EXPECT_LE(p.fraction(), 1.0);
  }

  constexpr int kFrames = 12;
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(kFrames);
  InbetweenRun run = RunInbetween(*stub_, request);
  ExpectValidAnimation(run, result.multimesh(), kFrames);
  EXPECT_EQ(run.messages[0].header().session_version(), result.session().version());

  // A new drawing invalidates the multimesh.
  v1::PutDrawingResponse put;
  ASSERT_TRUE(PutPolylines(result.session(), SquareOutline(0, 0, 50), &put).ok());
  EXPECT_EQ(put.session().stage(), v1::STAGE_DRAWINGS);
  EXPECT_EQ(RunInbetween(*stub_, request).status.error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);
}

TEST_F(InbetweenServiceTest, BuildWithStaleVersionIsAborted) {
  v1::Session session = SessionWithExamples();
  v1::Session stale = session;
  stale.set_version(session.version() - 1);
  EXPECT_EQ(RunBuild(*stub_, stale).status.error_code(), grpc::StatusCode::ABORTED);
}

TEST_F(InbetweenServiceTest, CancellingAnInbetweenStreamStopsItAndTheServerKeepsServing) {
  v1::Session session = ImportTwoSquares();
  {
    grpc::ClientContext context;
    v1::InbetweenRequest request;
    request.set_session_id(session.id());
    request.mutable_parameters()->set_frames(kMaxFrames);
    auto reader = stub_->Inbetween(&context, request);
    v1::InbetweenResponse message;
    ASSERT_TRUE(reader->Read(&message));
    EXPECT_TRUE(message.has_header());
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(reader->Read(&message));
      EXPECT_EQ(message.frame().index(), static_cast<uint32_t>(i));
    }
    context.TryCancel();
    int more = 0;
    while (reader->Read(&message)) ++more;
    EXPECT_LT(more, kMaxFrames - 3);
    grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::CANCELLED);
  }
  // Still serving: the same session animates again.
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(5);
  InbetweenRun run = RunInbetween(*stub_, request);
  EXPECT_TRUE(run.status.ok()) << run.status.error_message();
  EXPECT_EQ(run.messages.size(), 6u);
}

TEST_F(InbetweenServiceTest, DeadlineStopsAnInbetweenStream) {
  v1::Session session = ImportTwoSquares();
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(200));
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(kMaxFrames);
  auto reader = stub_->Inbetween(&context, request);
  v1::InbetweenResponse message;
  // Read slowly so that the stream cannot finish before the deadline.
  while (reader->Read(&message)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_FALSE(CreateSession().id().empty());
}

}  // namespace
}  // namespace inbetween::server::testing
