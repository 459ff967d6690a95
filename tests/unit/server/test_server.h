// Shared fixture for server tests: a real in-process InbetweenServer and a stub on its channel,
// plus helpers that build sessions in common states.
#pragma once

#include <grpcpp/client_context.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/support/byte_buffer.h>
#include <gtest/gtest.h>

#include <fstream>
#include <future>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "inbetween/v1/inbetween.grpc.pb.h"
#include "server/drawing_import.h"
#include "server/inbetween_server.h"
#include "server/session_state.h"

namespace inbetween::server::testing {

namespace v1 = ::inbetween::v1;

// grpc.health.v1.Health/Check through a generic stub (Debian ships no generated health proto):
// the request is `string service = 1`, the reply `ServingStatus status = 1` (SERVING = 1).
// Returns the status value, or -1 on an RPC error.
inline int HealthCheck(const std::shared_ptr<grpc::Channel>& channel, const std::string& service) {
  std::string request_bytes;
  if (!service.empty()) {
    request_bytes.push_back(0x0a);                               // field 1, length-delimited
    request_bytes.push_back(static_cast<char>(service.size()));  // < 128: one varint byte
    request_bytes += service;
  }
  grpc::Slice slice(request_bytes);
  grpc::ByteBuffer request(&slice, 1);
  grpc::ByteBuffer response;
  grpc::GenericStub stub(channel);
  grpc::ClientContext context;
  std::promise<grpc::Status> done;
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &request, &response,
                 [&done](grpc::Status status) { done.set_value(status); });
  grpc::Status status = done.get_future().get();
  if (!status.ok()) return -1;
  std::vector<grpc::Slice> slices;
  EXPECT_TRUE(response.Dump(&slices).ok());
  std::string bytes;
  for (const grpc::Slice& s : slices)
    bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  if (bytes.empty()) return 0;  // UNKNOWN (the default) is encoded as nothing
  EXPECT_EQ(bytes.size(), 2u);
  EXPECT_EQ(bytes[0], 0x08);  // field 1, varint
  return bytes[1];
}

inline std::string ReadExample(const std::string& relative) {
  std::ifstream in(std::string(INBETWEEN_SOURCE_DIR) + "/" + relative);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// An axis-aligned square outline with positive signed area (y down).
inline v1::TopologyElement SquareOutline(double x0, double y0, double size) {
  v1::TopologyElement element;
  element.set_kind(v1::ELEMENT_KIND_OUTLINE);
  for (auto [x, y] :
       {std::pair{x0, y0}, {x0 + size, y0}, {x0 + size, y0 + size}, {x0, y0 + size}}) {
    v1::Point* p = element.mutable_polyline()->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  return element;
}

// Two art layers using every field: a filled square (even-odd) and a dashed, round-capped
// stroke with bevel joins, whose coordinates are not exact decimals.
inline std::vector<solver::ArtLayer> SampleArt() {
  solver::ArtLayer fill;
  fill.id = "body";
  fill.name = "torso";
  fill.paths = {{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, true}};
  fill.fill = solver::FillPaint{.rgb = 0x3b7dd8, .opacity = 0.5, .even_odd = true};
  fill.opacity = 0.75;
  solver::ArtLayer stroke;
  stroke.paths = {{{{0.1 + 0.2, 1.0 / 3.0}, {2, 2}}, false}, {{{3, 3}, {4, 3}, {4, 4}}, true}};
  stroke.stroke = solver::StrokePaint{.rgb = 0x102030,
                                      .opacity = 0.25,
                                      .width = 1.5,
                                      .cap = solver::LineCap::kRound,
                                      .join = solver::LineJoin::kBevel,
                                      .miter_limit = 10,
                                      .dashes = {2, 1},
                                      .dash_offset = 0.5};
  return {fill, stroke};
}

// Every field of two drawings' art is equal (doubles exactly).
inline void ExpectSameArt(const std::vector<solver::ArtLayer>& got,
                          const std::vector<solver::ArtLayer>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) {
    SCOPED_TRACE(::testing::Message() << "layer " << i);
    const solver::ArtLayer& a = got[i];
    const solver::ArtLayer& b = want[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.name, b.name);
    ASSERT_EQ(a.paths.size(), b.paths.size());
    for (size_t k = 0; k < a.paths.size(); ++k) {
      EXPECT_EQ(a.paths[k].points, b.paths[k].points) << "path " << k;
      EXPECT_EQ(a.paths[k].closed, b.paths[k].closed) << "path " << k;
    }
    EXPECT_EQ(a.opacity, b.opacity);
    ASSERT_EQ(a.fill.has_value(), b.fill.has_value());
    if (a.fill) {
      EXPECT_EQ(a.fill->rgb, b.fill->rgb);
      EXPECT_EQ(a.fill->opacity, b.fill->opacity);
      EXPECT_EQ(a.fill->even_odd, b.fill->even_odd);
    }
    ASSERT_EQ(a.stroke.has_value(), b.stroke.has_value());
    if (a.stroke) {
      EXPECT_EQ(a.stroke->rgb, b.stroke->rgb);
      EXPECT_EQ(a.stroke->opacity, b.stroke->opacity);
      EXPECT_EQ(a.stroke->width, b.stroke->width);
      EXPECT_EQ(a.stroke->cap, b.stroke->cap);
      EXPECT_EQ(a.stroke->join, b.stroke->join);
      EXPECT_EQ(a.stroke->miter_limit, b.stroke->miter_limit);
      EXPECT_EQ(a.stroke->dashes, b.stroke->dashes);
      EXPECT_EQ(a.stroke->dash_offset, b.stroke->dash_offset);
    }
  }
}

// A stored state (for store tests): one drawing (a unit square) and a two-triangle multimesh.
inline SessionState StoredSessionState(const std::string& owner) {
  SessionState state;
  state.owner = owner;
  state.session.set_display_name("squares");
  v1::Drawing* drawing = state.session.add_drawings();
  drawing->set_id(1);
  *drawing->add_elements() = SquareOutline(0, 0, 1);
  drawing->mutable_elements(0)->set_id(1);
  auto imported = ImportDrawingElements(*drawing, "drawing 1", 1);
  EXPECT_TRUE(imported.ok()) << imported.status();
  if (imported.ok()) state.parsed.push_back(imported->parsed);
  state.next_drawing_id = 2;
  auto mesh = std::make_shared<solver::Multimesh>();
  mesh->triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh->shapes = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{0, 0}, {2, 0}, {2, 2}, {0, 2}}};
  mesh->boundary = {0, 1, 2, 3};
  mesh->boundary_loops = {{0, 1, 2, 3}};
  state.multimesh = mesh;
  state.session.set_stage(v1::STAGE_MULTIMESH);
  return state;
}

class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.shutdown_grace = std::chrono::milliseconds(500);
    auto server = InbetweenServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = *std::move(server);
    stub_ = v1::Inbetween::NewStub(server_->InProcessChannel());
  }

  v1::Session CreateSession(const std::string& name = "test") {
    grpc::ClientContext context;
    v1::CreateSessionRequest request;
    request.set_display_name(name);
    v1::CreateSessionResponse response;
    grpc::Status status = stub_->CreateSession(&context, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.session();
  }

  grpc::Status PutSvg(const v1::Session& session, const std::string& name, const std::string& svg,
                      v1::PutDrawingResponse* response) {
    grpc::ClientContext context;
    v1::PutDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.mutable_drawing()->set_name(name);
    request.mutable_drawing()->set_svg(svg);
    return stub_->PutDrawing(&context, request, response);
  }

  grpc::Status PutPolylines(const v1::Session& session, const v1::TopologyElement& outline,
                            v1::PutDrawingResponse* response) {
    grpc::ClientContext context;
    v1::PutDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    *request.mutable_drawing()->mutable_polylines()->add_elements() = outline;
    return stub_->PutDrawing(&context, request, response);
  }

  // A session with the square and hexagon examples as its two drawings.
  v1::Session SessionWithExamples() {
    v1::Session session = CreateSession("square-hexagon");
    for (const char* name : {"square", "hexagon"}) {
      v1::PutDrawingResponse response;
      grpc::Status status =
          PutSvg(session, name,
                 ReadExample(std::string("examples/square_hexagon/") + name + ".svg"), &response);
      EXPECT_TRUE(status.ok()) << status.error_message();
      session = response.session();
    }
    return session;
  }

  // A session imported from an archive: two square drawings and a hand-made two-triangle
  // multimesh (shape 2 = shape 1 scaled by 2), so stream tests do not depend on meshing.
  // key_times: empty = unset on both drawings; otherwise one value per drawing, < 0 = unset.
  v1::Session ImportTwoSquares(double scale = 2.0, std::vector<double> key_times = {}) {
    v1::SessionArchive archive;
    archive.set_format_version(1);
    v1::Session* session = archive.mutable_session();
    session->set_display_name("two squares");
    session->set_version(7);
    for (uint32_t i = 1; i <= 2; ++i) {
      v1::Drawing* drawing = session->add_drawings();
      drawing->set_id(i);
      drawing->set_name("square " + std::to_string(i));
      *drawing->add_elements() = SquareOutline(0, 0, i == 1 ? 1.0 : scale);
      drawing->mutable_elements(0)->set_id(1);
      if (!key_times.empty() && key_times[i - 1] >= 0) drawing->set_key_time(key_times[i - 1]);
    }
    session->set_stage(v1::STAGE_MULTIMESH);
    v1::Multimesh* mesh = archive.mutable_multimesh();
    for (auto [a, b, c] : {std::tuple{0u, 1u, 2u}, {0u, 2u, 3u}}) {
      v1::Triangle* t = mesh->add_triangles();
      t->set_a(a);
      t->set_b(b);
      t->set_c(c);
    }
    for (double s : {1.0, scale}) {
      v1::ShapeGeometry* shape = mesh->add_shapes();
      *shape->mutable_vertices() = SquareOutline(0, 0, s).polyline().points();
    }
    for (uint32_t v : {0u, 1u, 2u, 3u}) mesh->add_boundary(v);

    grpc::ClientContext context;
    v1::ImportSessionRequest request;
    archive.SerializeToString(request.mutable_data());
    v1::ImportSessionResponse response;
    grpc::Status status = stub_->ImportSession(&context, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.session();
  }

  std::unique_ptr<InbetweenServer> server_;
  std::unique_ptr<v1::Inbetween::Stub> stub_;
};

}  // namespace inbetween::server::testing
