// libFuzzer: every RPC of inbetween.v1.Inbetween with a request decoded from random bytes,
// through the real handlers of an in-process InbetweenServer. Byte 0 picks the method and two
// flags: 0x40 points the request at a fresh copy of a real session (two drawings, a built
// multimesh; imported from an archive made at start-up, and reused by later inputs while no
// call changed it), 0x80 also sets its current expected_version, so mutations go deep instead
// of stopping at NOT_FOUND / ABORTED. The rest is the serialized request (EditTopology: one
// edit). Findings: crashes, sanitizer reports, hangs (calls have a 3 s deadline, after which the
// handlers must stop), and INTERNAL or UNKNOWN statuses (the API reserves INTERNAL for bugs).
#include <grpcpp/grpcpp.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "inbetween/v1/inbetween.grpc.pb.h"
#include "server/inbetween_server.h"

namespace {

namespace v1 = ::inbetween::v1;
using inbetween::server::InbetweenServer;

constexpr char kSquare[] =
    "<svg xmlns=\"http://www.w3.org/2000/svg\"><path d=\"M 10 10 H 110 V 110 H 10 Z\"/></svg>";
constexpr char kHexagon[] =
    "<svg xmlns=\"http://www.w3.org/2000/svg\"><path d=\"M 115 60 L 87.5 107.631 L 32.5 107.631 "
    "L 5 60 L 32.5 12.369 L 87.5 12.369 Z\"/></svg>";

struct World {
  std::unique_ptr<InbetweenServer> server;
  std::unique_ptr<v1::Inbetween::Stub> stub;
  std::string archive;  // ExportSession of the template session
};

// A bound on the work of an OptimizeComesh (as the deadline is): at most 2 outer and 8 inner
// iterations, so one input does not take the time of hundreds. Every path of the optimizer is
// still reached (a topology pass, inner steps, convergence, limits) on the small mesh.
void BoundComesh(v1::ComeshParameters* c) {
  auto at_most = [](uint32_t n, uint32_t bound) { return n == 0 || n > bound ? bound : n; };
  c->set_max_outer_iterations(at_most(c->max_outer_iterations(), 2));
  c->set_max_inner_iterations(at_most(c->max_inner_iterations(), 8));
}

void Require(const grpc::Status& s, const char* what) {
  if (!s.ok()) {
    std::fprintf(stderr, "rpc_fuzz set-up: %s: %s\n", what, s.error_message().c_str());
    std::abort();
  }
}

World& GetWorld() {
  static World* world = [] {
    auto* w = new World;
    inbetween::server::ServerOptions options;
    options.reflection = false;
    // Small limits keep one input cheap (the heavy RPCs mesh, optimize and solve within them):
    // throughput is what lets a run reach millions of inputs, and a refusal at a limit is as
    // much a path to test as the work below it.
    options.service.limits.max_frames = 16;
    options.service.limits.max_mesh_vertices = 120;
    options.service.limits.max_drawing_points = 2000;
    absl::StatusOr<std::unique_ptr<InbetweenServer>> server = InbetweenServer::Start(options);
    if (!server.ok()) std::abort();
    w->server = *std::move(server);
    w->stub = v1::Inbetween::NewStub(w->server->InProcessChannel());
    grpc::ClientContext c1;
    v1::CreateSessionRequest create;
    BoundComesh(create.mutable_parameters()->mutable_comesh());
    v1::CreateSessionResponse created;
    Require(w->stub->CreateSession(&c1, create, &created), "CreateSession");
    uint64_t version = created.session().version();
    for (const char* svg : {kSquare, kHexagon}) {
      grpc::ClientContext c;
      v1::PutDrawingRequest put;
      put.set_session_id(created.session().id());
      put.set_expected_version(version);
      put.mutable_drawing()->set_svg(svg);
      v1::PutDrawingResponse resp;
      Require(w->stub->PutDrawing(&c, put, &resp), "PutDrawing");
      version = resp.session().version();
    }
    grpc::ClientContext cb;
    v1::BuildMultimeshRequest build;
    build.set_session_id(created.session().id());
    build.set_expected_version(version);
    build.mutable_meshing()->set_boundary_vertices(8);  // the smallest mesh: cheap to import
    auto reader = w->stub->BuildMultimesh(&cb, build);
    v1::BuildMultimeshResponse event;
    while (reader->Read(&event)) {
    }
    Require(reader->Finish(), "BuildMultimesh");
    grpc::ClientContext ce;
    v1::ExportSessionRequest ex;
    ex.set_session_id(created.session().id());
    v1::ExportSessionResponse exported;
    Require(w->stub->ExportSession(&ce, ex, &exported), "ExportSession");
    w->archive = exported.data();
    // Stop the server before LeakSanitizer's check at exit: gRPC's ThreadManager creates and
    // reaps worker threads on its own, and a worker still being reaped when the run ends was
    // reported as a leak (96 + 40 bytes from grpc::ThreadManager::MainWorkLoop, after a
    // 261,188-run session of -max_total_time=4200). LeakSanitizer's own exit handler was
    // registered first, so this one runs before it.
    std::atexit([] {
      World& w = GetWorld();
      w.stub.reset();
      w.server->Shutdown();
      w.server->Wait();
    });
    return w;
  }();
  return *world;
}

void SetIfPresent(google::protobuf::Message* m, const char* field, const std::string& value) {
  const auto* f = m->GetDescriptor()->FindFieldByName(field);
  if (f && f->type() == google::protobuf::FieldDescriptor::TYPE_STRING) {
    m->GetReflection()->SetString(m, f, value);
  }
}
void SetIfPresent(google::protobuf::Message* m, const char* field, uint64_t value) {
  const auto* f = m->GetDescriptor()->FindFieldByName(field);
  if (f && f->type() == google::protobuf::FieldDescriptor::TYPE_UINT64) {
    m->GetReflection()->SetUInt64(m, f, value);
  }
}

void Check(const grpc::Status& s, int method) {
  if (s.error_code() == grpc::StatusCode::INTERNAL || s.error_code() == grpc::StatusCode::UNKNOWN) {
    std::fprintf(stderr, "method %d: status %d: %s\n", method, s.error_code(),
                 s.error_message().c_str());
    std::abort();
  }
}

std::unique_ptr<grpc::ClientContext> Context() {
  auto ctx = std::make_unique<grpc::ClientContext>();
  ctx->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(3));
  return ctx;
}

template <typename Reader, typename Response>
grpc::Status Drain(Reader reader, grpc::ClientContext* ctx) {
  Response r;
  int n = 0;
  while (reader->Read(&r)) {
    if (++n > 100000) ctx->TryCancel();
  }
  return reader->Finish();
}

// Parses `bytes` into a request of type T, aims it at `session`/`version` when asked, calls.
template <typename T>
bool Prepare(const uint8_t* data, size_t size, T* request, const std::string& session,
             uint64_t version, bool use_version) {
  if (!request->ParseFromArray(data, static_cast<int>(size))) return false;
  if (!session.empty()) SetIfPresent(request, "session_id", session);
  if (use_version) SetIfPresent(request, "expected_version", version);
  return true;
}

// Seeds (scripts/fuzz sets INBETWEEN_FUZZ_SEEDS=DIR): one well-formed request per method,
// aimed at the imported session with its version (selector 0xC0 | method).
void WriteSeeds(const std::string& dir) {
  auto write = [&](int method, const google::protobuf::Message& m) {
    const std::string path = dir + "/seed_" + std::to_string(method);
    if (FILE* f = std::fopen(path.c_str(), "wb")) {
      const std::string bytes =
          std::string(1, static_cast<char>(0xC0 | method)) + m.SerializeAsString();
      std::fwrite(bytes.data(), 1, bytes.size(), f);
      std::fclose(f);
    }
  };
  v1::CreateSessionRequest create;
  create.set_display_name("seed");
  create.mutable_parameters()->mutable_inbetween()->set_frames(8);
  write(0, create);
  v1::GetSessionRequest get;
  get.set_full(true);
  write(1, get);
  v1::ListSessionsRequest list;
  list.set_page_size(2);
  write(2, list);
  write(3, v1::DeleteSessionRequest());
  write(4, v1::ExportSessionRequest());
  v1::ImportSessionRequest imp;
  imp.set_data(GetWorld().archive);
  write(5, imp);
  v1::PutDrawingRequest put;
  put.mutable_drawing()->set_svg(kHexagon);
  v1::TopologyElement* cut = put.add_topology();
  cut->set_kind(v1::ELEMENT_KIND_OPENING);
  for (auto [x, y] : {std::pair{40.0, 60.0}, {80.0, 60.0}}) {
    v1::Point* p = cut->mutable_polyline()->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  write(6, put);
  v1::RemoveDrawingRequest remove;
  remove.set_drawing_id(2);
  write(7, remove);
  v1::TopologyEdit edit;
  edit.set_drawing_id(1);
  *edit.mutable_add() = *cut;
  write(8, edit);
  v1::SetCorrespondencesRequest marks;
  v1::Correspondence* c = marks.add_correspondences();
  for (auto [x, y] : {std::pair{10.0, 10.0}, {32.5, 12.369}}) {
    v1::Point* p = c->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  write(9, marks);
  v1::BuildMultimeshRequest build;
  build.mutable_meshing()->set_boundary_vertices(16);
  write(10, build);
  v1::OptimizeComeshRequest optimize;
  optimize.mutable_comesh()->set_max_outer_iterations(1);
  optimize.mutable_comesh()->set_max_inner_iterations(2);
  write(11, optimize);
  v1::InbetweenRequest inbetween;
  inbetween.mutable_parameters()->set_frames(6);
  inbetween.mutable_parameters()->set_method(v1::METHOD_ZHU17);
  write(12, inbetween);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  if (const char* dir = std::getenv("INBETWEEN_FUZZ_SEEDS")) WriteSeeds(dir);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  World& w = GetWorld();
  const uint8_t selector = data[0];
  const int method = selector % 13;
  data += 1;
  size -= 1;

  // The copy of the template session; it serves the next input too when the call left it
  // unchanged (below). An import costs more than most calls (~3 ms of ~3.5 under ASan).
  static std::string pooled;
  static uint64_t pooled_version = 0;
  std::string session;
  uint64_t version = 0;
  if (selector & 0x40) {
    if (pooled.empty()) {
      // Set-up, not under test: no 3 s deadline. A two-core machine busy with a build starved a
      // nice-19 run so long that the import missed it (DEADLINE_EXCEEDED, and Require aborted);
      // a real hang is still caught by libFuzzer's -timeout.
      auto ctx = std::make_unique<grpc::ClientContext>();
      v1::ImportSessionRequest imp;
      imp.set_data(w.archive);
      v1::ImportSessionResponse resp;
      Require(w.stub->ImportSession(ctx.get(), imp, &resp), "ImportSession");
      pooled = resp.session().id();
      pooled_version = resp.session().version();
    }
    session = pooled;
    version = pooled_version;
  }
  const bool use_version = selector & 0x80;
  std::string created;  // a session the call created, deleted afterwards
  auto ctx = Context();
  grpc::Status status;
  switch (method) {
    case 0: {
      v1::CreateSessionRequest r;
      v1::CreateSessionResponse resp;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = w.stub->CreateSession(ctx.get(), r, &resp);
      created = resp.session().id();
      break;
    }
    case 1: {
      v1::GetSessionRequest r;
      v1::GetSessionResponse resp;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = w.stub->GetSession(ctx.get(), r, &resp);
      break;
    }
    case 2: {
      v1::ListSessionsRequest r;
      v1::ListSessionsResponse resp;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = w.stub->ListSessions(ctx.get(), r, &resp);
      break;
    }
    case 3: {
      v1::DeleteSessionRequest r;
      v1::DeleteSessionResponse resp;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = w.stub->DeleteSession(ctx.get(), r, &resp);
      break;
    }
    case 4: {
      v1::ExportSessionRequest r;
      v1::ExportSessionResponse resp;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = w.stub->ExportSession(ctx.get(), r, &resp);
      break;
    }
    case 5: {
      v1::ImportSessionRequest r;
      v1::ImportSessionResponse resp;
      if (!r.ParseFromArray(data, static_cast<int>(size))) break;
      status = w.stub->ImportSession(ctx.get(), r, &resp);
      created = resp.session().id();
      break;
    }
    case 6: {
      v1::PutDrawingRequest r;
      v1::PutDrawingResponse resp;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = w.stub->PutDrawing(ctx.get(), r, &resp);
      break;
    }
    case 7: {
      v1::RemoveDrawingRequest r;
      v1::RemoveDrawingResponse resp;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = w.stub->RemoveDrawing(ctx.get(), r, &resp);
      break;
    }
    case 8: {
      v1::TopologyEdit r;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      auto stream = w.stub->EditTopology(ctx.get());
      v1::TopologyState state;
      // The one edit goes with the half-close (as the web gateway's EditTopologyOnce sends
      // it). A separate WritesDone after the handler already answered an error leaked both
      // calls' arenas (~35 kB under ASan) in gRPC's in-process transport (Debian's 1.51; the
      // same calls over TCP stay flat): RSS grew with every such input (docs/hardening.md).
      if (stream->Write(r, grpc::WriteOptions().set_last_message())) stream->Read(&state);
      while (stream->Read(&state)) {
      }
      status = stream->Finish();
      break;
    }
    case 9: {
      v1::SetCorrespondencesRequest r;
      v1::SetCorrespondencesResponse resp;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = w.stub->SetCorrespondences(ctx.get(), r, &resp);
      break;
    }
    case 10: {
      v1::BuildMultimeshRequest r;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = Drain<decltype(w.stub->BuildMultimesh(ctx.get(), r)), v1::BuildMultimeshResponse>(
          w.stub->BuildMultimesh(ctx.get(), r), ctx.get());
      break;
    }
    case 11: {
      v1::OptimizeComeshRequest r;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      // (Unset parameters mean the session's, which the template session bounds the same way.)
      if (r.has_comesh()) BoundComesh(r.mutable_comesh());
      status = Drain<decltype(w.stub->OptimizeComesh(ctx.get(), r)), v1::OptimizeComeshResponse>(
          w.stub->OptimizeComesh(ctx.get(), r), ctx.get());
      break;
    }
    default: {
      v1::InbetweenRequest r;
      if (!Prepare(data, size, &r, session, version, use_version)) break;
      status = Drain<decltype(w.stub->Inbetween(ctx.get(), r)), v1::InbetweenResponse>(
          w.stub->Inbetween(ctx.get(), r), ctx.get());
      break;
    }
  }
  Check(status, method);
  // Every mutation moves a session's version on, except OptimizeComesh's checkpoint (kept at the
  // same version for a later resume): after any other method, the same version means the same
  // session, as fresh as a new import.
  bool unchanged = false;
  if (!session.empty() && method != 11) {
    auto c = Context();
    v1::GetSessionRequest get;
    get.set_session_id(session);
    v1::GetSessionResponse resp;
    unchanged = w.stub->GetSession(c.get(), get, &resp).ok() && resp.session().version() == version;
  }
  std::string stale;  // the copy the call changed (or may have): deleted, a new one next time
  if (!session.empty() && !unchanged) {
    stale = session;
    pooled.clear();
  }
  for (const std::string& id : {stale, created}) {
    if (id.empty()) continue;
    auto c = Context();
    v1::DeleteSessionRequest del;
    del.set_session_id(id);
    v1::DeleteSessionResponse resp;
    w.stub->DeleteSession(c.get(), del, &resp);
  }
  return 0;
}
