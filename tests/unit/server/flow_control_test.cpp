// Inbetween respects flow control: the handler writes each frame as it is solved and a write
// blocks while the client does not read, so a slow client slows the solver instead of the server
// buffering frames without bound. Over loopback TCP (HTTP/2 windows and socket buffers are what
// a remote client has), a client that stops reading after the first frame finds the server
// parked a bounded number of frames ahead; after it reads on, every frame arrives in order.
#include <grpcpp/create_channel.h>
#include <grpcpp/security/credentials.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>

#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

// A session holding an n x n grid multimesh (two shapes: the grid and the grid stretched), so a
// frame is n^2 vertices (~20 bytes each on the wire).
v1::ImportSessionRequest GridArchive(int n) {
  v1::SessionArchive archive;
  archive.set_format_version(1);
  v1::Session* session = archive.mutable_session();
  session->set_display_name("grid");
  session->set_version(1);
  for (uint32_t i = 1; i <= 2; ++i) {
    v1::Drawing* drawing = session->add_drawings();
    drawing->set_id(i);
    *drawing->add_elements() = SquareOutline(0, 0, n - 1);
    drawing->mutable_elements(0)->set_id(1);
  }
  session->set_stage(v1::STAGE_MULTIMESH);
  v1::Multimesh* mesh = archive.mutable_multimesh();
  auto id = [n](int i, int j) { return static_cast<uint32_t>(j * n + i); };
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      for (auto [a, b, c] : {std::tuple{id(i, j), id(i + 1, j), id(i + 1, j + 1)},
                             {id(i, j), id(i + 1, j + 1), id(i, j + 1)}}) {
        v1::Triangle* t = mesh->add_triangles();
        t->set_a(a);
        t->set_b(b);
        t->set_c(c);
      }
    }
  }
  for (double stretch : {1.0, 1.5}) {
    v1::ShapeGeometry* shape = mesh->add_shapes();
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        v1::Point* p = shape->add_vertices();
        p->set_x(stretch * i);
        p->set_y(j);
      }
    }
  }
  // The boundary loop, counter-clockwise in y-down raw coordinates like the triangles.
  for (int i = 0; i < n - 1; ++i) mesh->add_boundary(id(i, 0));
  for (int j = 0; j < n - 1; ++j) mesh->add_boundary(id(n - 1, j));
  for (int i = n - 1; i > 0; --i) mesh->add_boundary(id(i, n - 1));
  for (int j = n - 1; j > 0; --j) mesh->add_boundary(id(0, j));
  v1::ImportSessionRequest request;
  archive.SerializeToString(request.mutable_data());
  return request;
}

TEST(FlowControlTest, ASlowClientSlowsTheSolver) {
  auto metrics = std::make_shared<Metrics>();
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.shutdown_grace = std::chrono::milliseconds(500);
  options.service.metrics = metrics;
  absl::StatusOr<std::unique_ptr<InbetweenServer>> server = InbetweenServer::Start(options);
  ASSERT_TRUE(server.ok()) << server.status();
  std::unique_ptr<v1::Inbetween::Stub> stub = v1::Inbetween::NewStub(grpc::CreateChannel(
      "127.0.0.1:" + std::to_string((*server)->port()), grpc::InsecureChannelCredentials()));

  v1::Session session;
  {
    grpc::ClientContext context;
    v1::ImportSessionResponse response;
    grpc::Status status = stub->ImportSession(&context, GridArchive(100), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    session = response.session();
  }
  constexpr int kFrames = 1000;  // 10,000 vertices each: ~200 kB a frame, ~200 MB in all
  grpc::ClientContext context;
  v1::InbetweenRequest request;
  request.set_session_id(session.id());
  request.mutable_parameters()->set_frames(kFrames);
  request.mutable_parameters()->set_method(v1::METHOD_LINEAR);  // the cheapest frames
  auto reader = stub->Inbetween(&context, request);
  v1::InbetweenResponse message;
  ASSERT_TRUE(reader->Read(&message));
  ASSERT_TRUE(message.has_header());
  ASSERT_TRUE(reader->Read(&message));
  ASSERT_TRUE(message.has_frame());

  // Not reading. Without flow control the solver would finish all frames in well under this
  // pause (a linear frame of this mesh costs ~0.1 ms to solve and ~1 ms to serialize).
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const uint64_t solved_while_paused = metrics->frames_solved();
  EXPECT_GE(solved_while_paused, 1u);
  std::printf("[ flow     ] %llu of %d frames solved while the client read 1\n",
              static_cast<unsigned long long>(solved_while_paused), kFrames);
  // Ahead by what the windows and socket buffers hold (a few MB, ~tens of frames), not all.
  EXPECT_LT(solved_while_paused, kFrames / 4) << "the server ran ahead of a client not reading";

  int frames = 1;
  uint32_t last = message.frame().index();
  while (reader->Read(&message)) {
    ASSERT_TRUE(message.has_frame());
    EXPECT_EQ(message.frame().index(), last + 1);
    last = message.frame().index();
    ++frames;
  }
  grpc::Status status = reader->Finish();
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(frames, kFrames);
  EXPECT_EQ(metrics->frames_solved(), static_cast<uint64_t>(kFrames));
}

}  // namespace
}  // namespace inbetween::server::testing
