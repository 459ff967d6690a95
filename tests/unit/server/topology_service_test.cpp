// The solver stages wired into the service: PutDrawing.topology (cuts and openings, graph-flow
// classes and errors), the EditTopology stream, correspondence marks at build time, and the
// OptimizeComesh stream (iterations, result, stored stage, cancellation, checkpoints and resume).
#include <gmock/gmock.h>
#include <google/protobuf/util/message_differencer.h>
#include <grpcpp/client_context.h>
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "solver/core/types.h"
#include "solver/mesh/validate.h"
#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

v1::TopologyElement Line(v1::ElementKind kind, std::vector<std::pair<double, double>> points) {
  v1::TopologyElement element;
  element.set_kind(kind);
  for (auto [x, y] : points) {
    v1::Point* p = element.mutable_polyline()->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  return element;
}

// A 10x10 square with a slit opening inside it: one component with one hole.
v1::TopologyElement InnerOpening() { return Line(v1::ELEMENT_KIND_OPENING, {{3, 5}, {7, 5}}); }

struct OptimizeRun {
  std::vector<v1::ComeshIteration> iterations;
  std::vector<v1::Progress> progress;
  v1::OptimizeComeshResult result;
  int results = 0;
  grpc::Status status;
};

OptimizeRun RunOptimize(v1::Inbetween::Stub& stub, const v1::OptimizeComeshRequest& request,
                        grpc::ClientContext* context) {
  OptimizeRun run;
  auto reader = stub.OptimizeComesh(context, request);
  v1::OptimizeComeshResponse message;
  while (reader->Read(&message)) {
    EXPECT_EQ(run.results, 0) << "a message after the result";
    if (message.has_iteration()) run.iterations.push_back(message.iteration());
    if (message.has_progress()) run.progress.push_back(message.progress());
    if (message.has_result()) {
      run.result = message.result();
      ++run.results;
    }
  }
  run.status = reader->Finish();
  return run;
}

class TopologyServiceTest : public ServerTest {
 protected:
  grpc::Status Put(const v1::Session& session, const v1::TopologyElement& outline,
                   std::vector<v1::TopologyElement> topology, v1::PutDrawingResponse* response) {
    grpc::ClientContext context;
    v1::PutDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    *request.mutable_drawing()->mutable_polylines()->add_elements() = outline;
    for (const v1::TopologyElement& e : topology) *request.add_topology() = e;
    return stub_->PutDrawing(&context, request, response);
  }

  // Two 10x10 squares (drawing 2 twice as large), no cuts.
  v1::Session TwoSquares() {
    v1::Session session = CreateSession("squares");
    for (double size : {10.0, 20.0}) {
      v1::PutDrawingResponse response;
      grpc::Status status = Put(session, SquareOutline(0, 0, size), {}, &response);
      EXPECT_TRUE(status.ok()) << status.error_message();
      session = response.session();
    }
    return session;
  }

  v1::BuildMultimeshResult Build(const v1::Session& session, grpc::Status* status) {
    grpc::ClientContext context;
    v1::BuildMultimeshRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    auto reader = stub_->BuildMultimesh(&context, request);
    v1::BuildMultimeshResponse message;
    v1::BuildMultimeshResult result;
    while (reader->Read(&message)) {
      if (message.has_result()) result = message.result();
    }
    *status = reader->Finish();
    return result;
  }
};

// ---------------------------------------------------------------------------------------------
// PutDrawing.topology

TEST_F(TopologyServiceTest, PutDrawingAddsCutsAndOpeningsWithIdsAndClass) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse response;
  grpc::Status status = Put(session, SquareOutline(0, 0, 10), {InnerOpening()}, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.drawing().elements_size(), 2);
  EXPECT_EQ(response.drawing().elements(0).id(), 1u);
  EXPECT_EQ(response.drawing().elements(0).kind(), v1::ELEMENT_KIND_OUTLINE);
  EXPECT_EQ(response.drawing().elements(1).id(), 2u);
  EXPECT_EQ(response.drawing().elements(1).kind(), v1::ELEMENT_KIND_OPENING);
  EXPECT_EQ(response.equivalence_class().components(), 1u);
  EXPECT_EQ(response.equivalence_class().holes(), 1u);
  // Stored with the session.
  ASSERT_EQ(response.session().drawings(0).elements_size(), 2);

  // A cut across the whole square splits it into two components.
  v1::PutDrawingResponse split;
  status = Put(response.session(), SquareOutline(0, 0, 10),
               {Line(v1::ELEMENT_KIND_CUT, {{5, -1}, {5, 11}})}, &split);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(split.equivalence_class().components(), 2u);
  EXPECT_EQ(split.equivalence_class().holes(), 0u);
}

TEST_F(TopologyServiceTest, PutDrawingTopologyErrorsNameTheFieldAndLocation) {
  v1::Session session = CreateSession();
  v1::PutDrawingResponse response;
  grpc::Status status = Put(session, SquareOutline(0, 0, 10),
                            {Line(v1::ELEMENT_KIND_OUTLINE, {{1, 1}, {2, 1}, {2, 2}})}, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("topology[0].kind"));

  v1::TopologyElement with_id = InnerOpening();
  with_id.set_id(4);
  status = Put(session, SquareOutline(0, 0, 10), {with_id}, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("topology[0].id"));

  status = Put(session, SquareOutline(0, 0, 10), {Line(v1::ELEMENT_KIND_CUT, {{1, 1}})}, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("topology[0] has 1 points"));

  // Graph-flow errors come from the solver with the drawing and the location.
  status = Put(session, SquareOutline(0, 0, 10), {Line(v1::ELEMENT_KIND_CUT, {{20, 20}, {30, 30}})},
               &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("drawing 1, cut 1 lies outside the shape"));

  status = Put(session, SquareOutline(0, 0, 10),
               {Line(v1::ELEMENT_KIND_CUT, {{2, 5}, {12, 5}, {12, 7}, {2, 7}})}, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("leaves the shape"));

  // Nothing was stored.
  grpc::ClientContext context;
  v1::GetSessionRequest get;
  get.set_session_id(session.id());
  v1::GetSessionResponse got;
  ASSERT_TRUE(stub_->GetSession(&context, get, &got).ok());
  EXPECT_EQ(got.session().version(), session.version());
}

// ---------------------------------------------------------------------------------------------
// EditTopology

TEST_F(TopologyServiceTest, EditTopologyStreamsRebuiltBoundariesAndClasses) {
  v1::Session session = TwoSquares();
  grpc::ClientContext context;
  auto stream = stub_->EditTopology(&context);
  v1::TopologyEdit edit;
  edit.set_session_id(session.id());
  edit.set_drawing_id(session.drawings(0).id());

  // Add an opening: drawing 1 gets a hole, the classes now differ (a warning).
  edit.set_expected_version(session.version());
  *edit.mutable_add() = InnerOpening();
  ASSERT_TRUE(stream->Write(edit));
  v1::TopologyState state;
  ASSERT_TRUE(stream->Read(&state));
  EXPECT_EQ(state.version(), session.version() + 1);
  EXPECT_EQ(state.drawing_id(), session.drawings(0).id());
  ASSERT_EQ(state.elements_size(), 2);
  const uint32_t opening_id = state.elements(1).id();
  EXPECT_EQ(opening_id, 2u);
  EXPECT_EQ(state.boundaries_size(), 2);      // the square and the slit around the opening
  EXPECT_EQ(state.cohesive_edges_size(), 1);  // one segment, two sides
  ASSERT_EQ(state.classes_size(), 2);
  EXPECT_EQ(state.classes(0).holes(), 1u);
  EXPECT_EQ(state.classes(1).holes(), 0u);
  ASSERT_EQ(state.warnings_size(), 1);
  EXPECT_THAT(state.warnings(0), HasSubstr("same class"));

  // Move it (two segments now).
  edit.set_expected_version(state.version());
  edit.mutable_move()->Clear();
  *edit.mutable_move() = Line(v1::ELEMENT_KIND_UNSPECIFIED, {{3, 5}, {5, 6}, {7, 5}});
  edit.mutable_move()->set_id(opening_id);
  ASSERT_TRUE(stream->Write(edit));
  ASSERT_TRUE(stream->Read(&state));
  EXPECT_EQ(state.cohesive_edges_size(), 2);
  EXPECT_EQ(state.elements(1).polyline().points_size(), 3);

  // Delete it: back to one class everywhere.
  edit.set_expected_version(state.version());
  edit.set_delete_element(opening_id);
  ASSERT_TRUE(stream->Write(edit));
  ASSERT_TRUE(stream->Read(&state));
  EXPECT_EQ(state.elements_size(), 1);
  EXPECT_EQ(state.boundaries_size(), 1);
  EXPECT_EQ(state.cohesive_edges_size(), 0);
  EXPECT_EQ(state.warnings_size(), 0);
  const uint64_t version = state.version();

  // A bad edit ends the stream with INVALID_ARGUMENT naming the element.
  edit.set_expected_version(version);
  *edit.mutable_add() = Line(v1::ELEMENT_KIND_CUT, {{20, 20}, {30, 30}});
  ASSERT_TRUE(stream->Write(edit));
  EXPECT_FALSE(stream->Read(&state));
  grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("add cut 2"));
  EXPECT_THAT(status.error_message(), HasSubstr("lies outside the shape"));

  // The session kept the last good edit; its multimesh stage is DRAWINGS.
  grpc::ClientContext get_context;
  v1::GetSessionRequest get;
  get.set_session_id(session.id());
  v1::GetSessionResponse got;
  ASSERT_TRUE(stub_->GetSession(&get_context, get, &got).ok());
  EXPECT_EQ(got.session().version(), version);
  EXPECT_EQ(got.session().drawings(0).elements_size(), 1);
}

TEST_F(TopologyServiceTest, EditTopologyStaleVersionIsAbortedAndUnknownElementInvalid) {
  v1::Session session = TwoSquares();
  {
    grpc::ClientContext context;
    auto stream = stub_->EditTopology(&context);
    v1::TopologyEdit edit;
    edit.set_session_id(session.id());
    edit.set_drawing_id(session.drawings(0).id());
    edit.set_expected_version(session.version() - 1);
    *edit.mutable_add() = InnerOpening();
    stream->Write(edit);
    stream->WritesDone();
    v1::TopologyState state;
    EXPECT_FALSE(stream->Read(&state));
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::ABORTED);
  }
  {
    grpc::ClientContext context;
    auto stream = stub_->EditTopology(&context);
    v1::TopologyEdit edit;
    edit.set_session_id(session.id());
    edit.set_drawing_id(session.drawings(0).id());
    edit.set_expected_version(session.version());
    edit.set_delete_element(42);
    stream->Write(edit);
    stream->WritesDone();
    v1::TopologyState state;
    EXPECT_FALSE(stream->Read(&state));
    grpc::Status status = stream->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("delete_element = 42"));
  }
  {
    grpc::ClientContext context;
    auto stream = stub_->EditTopology(&context);
    v1::TopologyEdit edit;
    edit.set_session_id("nope");
    edit.set_drawing_id(1);
    edit.set_expected_version(1);
    edit.set_delete_element(1);
    stream->Write(edit);
    stream->WritesDone();
    v1::TopologyState state;
    EXPECT_FALSE(stream->Read(&state));
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::NOT_FOUND);
  }
  // A stream without edits is fine.
  grpc::ClientContext context;
  auto stream = stub_->EditTopology(&context);
  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
}

TEST_F(TopologyServiceTest, BuildUsesOpeningsOnEveryDrawing) {
  v1::Session session = CreateSession();
  for (double size : {10.0, 14.0}) {
    v1::PutDrawingResponse response;
    grpc::Status status =
        Put(session, SquareOutline(0, 0, size),
            {Line(v1::ELEMENT_KIND_OPENING, {{size * 0.3, size * 0.5}, {size * 0.7, size * 0.5}})},
            &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    session = response.session();
  }
  grpc::Status status;
  v1::BuildMultimeshResult result = Build(session, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(result.multimesh().cohesive_edges_size(), 0);
  EXPECT_GE(result.stats().map_energy(), 2.0 - 1e-9);  // 2 = conformal
  EXPECT_GT(result.stats().mesh_energy(), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Correspondences

TEST_F(TopologyServiceTest, CorrespondenceMarksPinTheBuiltMesh) {
  v1::Session session = SessionWithExamples();  // square (10..110), hexagon (radius 55)
  grpc::ClientContext context;
  v1::SetCorrespondencesRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  v1::Correspondence* mark = request.add_correspondences();
  for (auto [x, y] : {std::pair{10.0, 10.0}, {115.0, 60.0}}) {
    v1::Point* p = mark->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  v1::SetCorrespondencesResponse response;
  grpc::Status status = stub_->SetCorrespondences(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();

  v1::BuildMultimeshResult result = Build(response.session(), &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const v1::Multimesh& mesh = result.multimesh();
  bool pinned = false;
  for (int v = 0; v < mesh.shapes(0).vertices_size(); ++v) {
    const v1::Point& a = mesh.shapes(0).vertices(v);
    const v1::Point& b = mesh.shapes(1).vertices(v);
    if (std::hypot(a.x() - 10, a.y() - 10) < 1e-6 && std::hypot(b.x() - 115, b.y() - 60) < 1e-6) {
      pinned = true;
    }
  }
  EXPECT_TRUE(pinned) << "no vertex sits on the mark in both shapes";
}

// ---------------------------------------------------------------------------------------------
// OptimizeComesh

TEST_F(TopologyServiceTest, OptimizeStreamsIterationsStoresTheResultAndInbetweenUsesIt) {
  v1::Session session = SessionWithExamples();
  {
    grpc::ClientContext context;
    v1::OptimizeComeshRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    EXPECT_EQ(RunOptimize(*stub_, request, &context).status.error_code(),
              grpc::StatusCode::FAILED_PRECONDITION);
  }
  grpc::Status status;
  v1::BuildMultimeshResult built = Build(session, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();

  v1::OptimizeComeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(built.session().version() - 1);
  {
    grpc::ClientContext context;
    EXPECT_EQ(RunOptimize(*stub_, request, &context).status.error_code(),
              grpc::StatusCode::ABORTED);
  }
  request.set_expected_version(built.session().version());
  request.mutable_comesh()->set_max_outer_iterations(1000 + 1);
  {
    grpc::ClientContext context;
    OptimizeRun bad = RunOptimize(*stub_, request, &context);
    EXPECT_EQ(bad.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(bad.status.error_message(), HasSubstr("comesh.max_outer_iterations"));
  }
  request.mutable_comesh()->set_max_outer_iterations(2);
  request.mutable_comesh()->set_outline_corner_degrees(-1.0);
  {
    grpc::ClientContext context;
    OptimizeRun bad = RunOptimize(*stub_, request, &context);
    EXPECT_EQ(bad.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(bad.status.error_message(), HasSubstr("comesh.outline_corner_degrees = -1"));
  }
  request.mutable_comesh()->clear_outline_corner_degrees();
  request.mutable_comesh()->set_max_inner_iterations(30);
  grpc::ClientContext context;
  OptimizeRun run = RunOptimize(*stub_, request, &context);
  ASSERT_TRUE(run.status.ok()) << run.status.error_message();
  ASSERT_EQ(run.results, 1);
  ASSERT_FALSE(run.iterations.empty());
  for (size_t i = 0; i < run.iterations.size(); ++i) {
    const v1::ComeshIteration& it = run.iterations[i];
    EXPECT_EQ(it.inner(), i + 1);
    EXPECT_GT(it.vertices(), 3u);
    EXPECT_GE(it.map_energy(), 2.0 - 1e-9);
    EXPECT_GT(it.mesh_energy(), 0.0);
    EXPECT_GT(it.objective(), 0.0);
  }
  const v1::OptimizeComeshResult& result = run.result;
  EXPECT_EQ(result.session().stage(), v1::STAGE_OPTIMIZED);
  // Checkpoints keep the version: the result is the one version step.
  EXPECT_EQ(result.session().version(), built.session().version() + 1);
  EXPECT_EQ(result.resumed_outer(), 0u);
  EXPECT_EQ(result.inner_iterations(), run.iterations.size());
  EXPECT_GE(result.stats().map_energy(), 2.0 - 1e-9);
  EXPECT_LE(result.stats().map_energy(), built.stats().map_energy() + 1e-9);
  EXPECT_EQ(result.stats().vertices(),
            static_cast<uint32_t>(result.multimesh().shapes(0).vertices_size()));
  EXPECT_EQ(result.stats().inverted_triangles(), 0u);
  EXPECT_EQ(result.session().multimesh_stats().map_energy(), result.stats().map_energy());

  // Inbetween runs on the optimized multimesh.
  grpc::ClientContext inbetween_context;
  v1::InbetweenRequest inbetween;
  inbetween.set_session_id(session.id());
  inbetween.mutable_parameters()->set_frames(4);
  auto reader = stub_->Inbetween(&inbetween_context, inbetween);
  v1::InbetweenResponse message;
  ASSERT_TRUE(reader->Read(&message));
  ASSERT_TRUE(message.has_header());
  EXPECT_EQ(message.header().triangles_size(), result.multimesh().triangles_size());
  EXPECT_EQ(message.header().session_version(), result.session().version());
  while (reader->Read(&message)) {
  }
  EXPECT_TRUE(reader->Finish().ok());
}

TEST_F(TopologyServiceTest, CancellingOptimizeStopsItAndKeepsTheSession) {
  v1::Session session = SessionWithExamples();
  {
    // A finer mesh so that the optimization runs long enough to be cancelled.
    grpc::ClientContext context;
    v1::BuildMultimeshRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.mutable_meshing()->set_boundary_vertices(300);
    request.mutable_meshing()->set_max_edge_relative(0.01);
    auto reader = stub_->BuildMultimesh(&context, request);
    v1::BuildMultimeshResponse message;
    while (reader->Read(&message)) {
      if (message.has_result()) session = message.result().session();
    }
    ASSERT_TRUE(reader->Finish().ok());
  }
  grpc::ClientContext context;
  v1::OptimizeComeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  request.mutable_comesh()->set_max_outer_iterations(1000);
  request.mutable_comesh()->set_max_inner_iterations(100000);
  request.mutable_comesh()->set_tolerance(1e-12);
  auto reader = stub_->OptimizeComesh(&context, request);
  v1::OptimizeComeshResponse message;
  ASSERT_TRUE(reader->Read(&message));
  const auto cancelled_at = std::chrono::steady_clock::now();
  context.TryCancel();
  while (reader->Read(&message)) {
    EXPECT_FALSE(message.has_result());
  }
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
  // The handler has stopped once a new call on the same session sees the old version.
  grpc::ClientContext get_context;
  v1::GetSessionRequest get;
  get.set_session_id(session.id());
  v1::GetSessionResponse got;
  ASSERT_TRUE(stub_->GetSession(&get_context, get, &got).ok());
  EXPECT_EQ(got.session().version(), session.version());
  EXPECT_EQ(got.session().stage(), v1::STAGE_MULTIMESH);
  // Generous bound (not a benchmark): the solver checks the token every iteration.
  EXPECT_LT(std::chrono::steady_clock::now() - cancelled_at, std::chrono::seconds(5));
}

// ---------------------------------------------------------------------------------------------
// OptimizeComesh checkpoints and resume (docs/api.md "Resuming OptimizeComesh")

class OptimizeResumeTest : public TopologyServiceTest {
 protected:
  // The square -> hexagon examples, built.
  v1::Session Built() {
    grpc::Status status;
    v1::BuildMultimeshResult built = Build(SessionWithExamples(), &status);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return built.session();
  }

  static v1::OptimizeComeshRequest Request(const v1::Session& session, bool resume) {
    v1::OptimizeComeshRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.set_resume(resume);
    request.mutable_comesh()->set_max_outer_iterations(8);
    request.mutable_comesh()->set_max_inner_iterations(200);
    return request;
  }

  OptimizeRun Optimize(const v1::OptimizeComeshRequest& request) {
    grpc::ClientContext context;
    return RunOptimize(*stub_, request, &context);
  }

  // Starts the optimization and cancels it at the first iteration after the first topology pass:
  // the pass's checkpoint is written before the next inner run starts. Returns the iterations
  // received.
  std::vector<v1::ComeshIteration> Interrupt(const v1::OptimizeComeshRequest& request) {
    grpc::ClientContext context;
    auto reader = stub_->OptimizeComesh(&context, request);
    v1::OptimizeComeshResponse message;
    std::vector<v1::ComeshIteration> iterations;
    bool passed = false;
    while (reader->Read(&message)) {
      EXPECT_FALSE(message.has_result()) << "the optimization ended before it was interrupted";
      if (message.has_progress() && message.progress().detail().starts_with("outer ")) {
        passed = true;
      }
      if (message.has_iteration()) {
        iterations.push_back(message.iteration());
        if (passed) break;
      }
    }
    context.TryCancel();
    while (reader->Read(&message)) {
    }
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
    EXPECT_TRUE(passed);
    // The handler notices the cancel within an iteration (and writes no checkpoint after it).
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    return iterations;
  }

  v1::Session Get(const std::string& id) {
    grpc::ClientContext context;
    v1::GetSessionRequest request;
    request.set_session_id(id);
    v1::GetSessionResponse response;
    EXPECT_TRUE(stub_->GetSession(&context, request, &response).ok());
    return response.session();
  }

  static void ExpectSameOptimization(const OptimizeRun& got, const OptimizeRun& want) {
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(got.result.multimesh(),
                                                                   want.result.multimesh()));
    EXPECT_EQ(got.result.inner_iterations(), want.result.inner_iterations());
    EXPECT_EQ(got.result.outer_iterations(), want.result.outer_iterations());
    EXPECT_EQ(got.result.stats().map_energy(), want.result.stats().map_energy());
    EXPECT_EQ(got.result.stats().mesh_energy(), want.result.stats().mesh_energy());
  }
};

TEST_F(OptimizeResumeTest, ResumeContinuesFromTheStoredCheckpointWithTheSameResult) {
  const v1::Session reference_session = Built();
  const OptimizeRun reference = Optimize(Request(reference_session, false));
  ASSERT_TRUE(reference.status.ok()) << reference.status.error_message();
  ASSERT_GE(reference.result.outer_iterations(), 2u) << "needs a pass after the checkpoint";

  const v1::Session session = Built();
  const std::vector<v1::ComeshIteration> before = Interrupt(Request(session, false));
  ASSERT_FALSE(before.empty());
  // The checkpoint is stored at the same version; what clients see is unchanged.
  const v1::Session interrupted = Get(session.id());
  EXPECT_EQ(interrupted.version(), session.version());
  EXPECT_EQ(interrupted.stage(), v1::STAGE_MULTIMESH);
  auto checkpointed = server_->store().Get(session.id());
  ASSERT_TRUE(checkpointed.ok());
  ASSERT_NE(checkpointed->comesh_checkpoint, nullptr);

  // The same request with resume: continues after pass 1, numbering on.
  const OptimizeRun resumed = Optimize(Request(session, true));
  ASSERT_TRUE(resumed.status.ok()) << resumed.status.error_message();
  EXPECT_EQ(resumed.result.resumed_outer(), 1u);
  EXPECT_GT(resumed.result.resumed_inner(), 0u);
  ASSERT_FALSE(resumed.iterations.empty());
  EXPECT_EQ(resumed.iterations.front().inner(), resumed.result.resumed_inner() + 1);
  EXPECT_EQ(resumed.iterations.front().outer(), 1u);
  EXPECT_LT(resumed.result.resumed_inner(), before.back().inner());
  ASSERT_FALSE(resumed.progress.empty());
  EXPECT_THAT(resumed.progress.front().detail(), HasSubstr("resumed after outer 1 at iteration"));
  ExpectSameOptimization(resumed, reference);
  // The iterations after the checkpoint equal the uninterrupted run's.
  ASSERT_EQ(resumed.iterations.size() + resumed.result.resumed_inner(),
            reference.iterations.size());
  for (const v1::ComeshIteration& it : resumed.iterations) {
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(
        it, reference.iterations[it.inner() - 1]))
        << "iteration " << it.inner();
  }
  EXPECT_EQ(resumed.result.session().version(), session.version() + 1);
  EXPECT_EQ(resumed.result.session().stage(), v1::STAGE_OPTIMIZED);
  // The result is a new version without the checkpoint: resuming again is a stale version.
  EXPECT_EQ(Optimize(Request(session, true)).status.error_code(), grpc::StatusCode::ABORTED);
  auto stored = server_->store().Get(session.id());
  ASSERT_TRUE(stored.ok());
  EXPECT_EQ(stored->comesh_checkpoint, nullptr);
}

TEST_F(OptimizeResumeTest, ResumeWithoutACheckpointStartsOver) {
  const v1::Session reference_session = Built();
  const OptimizeRun reference = Optimize(Request(reference_session, false));
  ASSERT_TRUE(reference.status.ok()) << reference.status.error_message();

  const v1::Session session = Built();
  const OptimizeRun run = Optimize(Request(session, true));
  ASSERT_TRUE(run.status.ok()) << run.status.error_message();
  EXPECT_EQ(run.result.resumed_outer(), 0u);
  EXPECT_EQ(run.result.resumed_inner(), 0u);
  ASSERT_FALSE(run.iterations.empty());
  EXPECT_EQ(run.iterations.front().inner(), 1u);
  for (const v1::Progress& p : run.progress) EXPECT_THAT(p.detail(), Not(HasSubstr("resumed")));
  ExpectSameOptimization(run, reference);
}

TEST_F(OptimizeResumeTest, CheckpointOfAnotherVersionOrOtherParametersIsIgnored) {
  const v1::Session reference_session = Built();
  const OptimizeRun reference = Optimize(Request(reference_session, false));
  ASSERT_TRUE(reference.status.ok()) << reference.status.error_message();

  const v1::Session session = Built();
  Interrupt(Request(session, false));
  auto stored = server_->store().Get(session.id());
  ASSERT_TRUE(stored.ok()) << stored.status();
  ASSERT_NE(stored->comesh_checkpoint, nullptr);
  EXPECT_EQ(stored->comesh_checkpoint->input_version, session.version());
  EXPECT_EQ(stored->comesh_checkpoint->stored_version, stored->session.version());
  EXPECT_EQ(stored->comesh_checkpoint->checkpoint.outer, 1);

  // Other comesh parameters: the checkpoint is not this run's, so the run starts over.
  {
    v1::Session other_parameters = Built();
    Interrupt(Request(other_parameters, false));
    v1::OptimizeComeshRequest request = Request(other_parameters, true);
    request.mutable_comesh()->set_max_inner_iterations(199);
    const OptimizeRun run = Optimize(request);
    ASSERT_TRUE(run.status.ok()) << run.status.error_message();
    EXPECT_EQ(run.result.resumed_outer(), 0u);
    ASSERT_FALSE(run.iterations.empty());
    EXPECT_EQ(run.iterations.front().inner(), 1u);
  }

  // Another write to the session (here: the same state written again, checkpoint and all, as
  // a writer that does not know about checkpoints would): the interrupted run's request is now
  // stale, resume or not.
  auto rewritten = server_->store().Put(*stored, stored->session.version());
  ASSERT_TRUE(rewritten.ok()) << rewritten.status();
  ASSERT_NE(rewritten->comesh_checkpoint, nullptr);
  EXPECT_EQ(Optimize(Request(session, true)).status.error_code(), grpc::StatusCode::ABORTED);

  // A checkpoint current with the session but of a run that started from another (older)
  // version, i.e. from another multimesh: a request at the current version ignores it.
  SessionState next = *rewritten;
  auto older = std::make_shared<StoredComeshCheckpoint>(*rewritten->comesh_checkpoint);
  older->stored_version = rewritten->session.version();
  next.comesh_checkpoint = older;
  auto current = server_->store().PutSameVersion(next, rewritten->session.version());
  ASSERT_TRUE(current.ok()) << current.status();
  ASSERT_EQ(current->session.version(), older->stored_version);
  const OptimizeRun run = Optimize(Request(current->session, true));
  ASSERT_TRUE(run.status.ok()) << run.status.error_message();
  EXPECT_EQ(run.result.resumed_outer(), 0u);
  ASSERT_FALSE(run.iterations.empty());
  EXPECT_EQ(run.iterations.front().inner(), 1u);
  ExpectSameOptimization(run, reference);
}

TEST_F(OptimizeResumeTest, RebuildingDropsTheCheckpoint) {
  const v1::Session session = Built();
  Interrupt(Request(session, false));
  const v1::Session interrupted = Get(session.id());
  grpc::Status status;
  v1::BuildMultimeshResult rebuilt = Build(interrupted, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  auto stored = server_->store().Get(session.id());
  ASSERT_TRUE(stored.ok());
  EXPECT_EQ(stored->comesh_checkpoint, nullptr);
  EXPECT_EQ(Optimize(Request(session, true)).status.error_code(), grpc::StatusCode::ABORTED);
}

}  // namespace
}  // namespace inbetween::server::testing
