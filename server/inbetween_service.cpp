// inbetween.v1.Inbetween handlers. Each one: validate -> session store / solver -> status.
// Sessions are copied out of the store, worked on unlocked, and put back with the version they
// were read at, so a concurrent mutation makes the later writer fail with ABORTED.
#include "server/inbetween_service.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "server/cancel_watcher.h"
#include "server/drawing_import.h"
#include "server/logging.h"
#include "server/parameters.h"
#include "server/proto_convert.h"
#include "server/status_mapping.h"
#include "server/stiffness_field.h"
#include "solver/interp/inbetweener.h"
#include "solver/interp/timing.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"

namespace inbetween::server {
namespace {

namespace v1 = ::inbetween::v1;
using Clock = std::chrono::steady_clock;

// Runs a handler body: catches anything thrown (a bug must not take the server down), maps the
// status once and logs one line. `session_id` is read after `body` ran (CreateSession sets it).
template <typename Body>
grpc::Status RunRpc(absl::string_view rpc, const std::string& session_id, Body&& body) {
  const Clock::time_point start = Clock::now();
  absl::Status status;
  try {
    status = body();
  } catch (const std::exception& e) {
    status = absl::InternalError(absl::StrCat(rpc, " failed: ", e.what()));
  } catch (...) {
    status = absl::InternalError(absl::StrCat(rpc, " failed with an unknown exception"));
  }
  grpc::Status out = ToGrpcStatus(status);
  LogRpc(rpc, session_id, out, std::chrono::duration<double>(Clock::now() - start).count());
  return out;
}

grpc::Status NotImplemented(absl::string_view rpc, const std::string& session_id) {
  grpc::Status status(grpc::StatusCode::UNIMPLEMENTED,
                      absl::StrCat(rpc, " is not implemented yet in this server version"));
  LogRpc(rpc, session_id, status, 0.0);
  return status;
}

absl::Status RequireSessionId(const std::string& id) {
  if (id.empty()) return absl::InvalidArgumentError("session_id is required");
  return absl::OkStatus();
}

absl::StatusOr<SessionState> Load(const SessionStore& store, const std::string& id) {
  if (absl::Status s = RequireSessionId(id); !s.ok()) return s;
  return store.Get(id);
}

// Load for a mutation: also checks expected_version against the current version.
absl::StatusOr<SessionState> LoadForUpdate(const SessionStore& store, const std::string& id,
                                           uint64_t expected_version) {
  absl::StatusOr<SessionState> state = Load(store, id);
  if (!state.ok()) return state.status();
  if (state->session.version() != expected_version) {
    return StaleVersionError(id, state->session.version(), expected_version);
  }
  return state;
}

// The session without drawing sources (SVG text can be large); elements stay.
v1::Session Compact(const v1::Session& session) {
  v1::Session out = session;
  for (v1::Drawing& drawing : *out.mutable_drawings()) drawing.clear_source();
  return out;
}

// The ListSessions summary: id, version, display_name, stage, timestamps.
v1::Session Summary(const v1::Session& session) {
  v1::Session out;
  out.set_id(session.id());
  out.set_version(session.version());
  out.set_display_name(session.display_name());
  out.set_stage(session.stage());
  out.set_created_unix_ms(session.created_unix_ms());
  out.set_updated_unix_ms(session.updated_unix_ms());
  return out;
}

// Any change to drawings or correspondences drops the multimesh built from them.
void InvalidateMultimesh(SessionState& state) {
  state.multimesh.reset();
  state.session.clear_multimesh_stats();
  state.session.set_stage(state.session.drawings_size() > 0 ? v1::STAGE_DRAWINGS
                                                            : v1::STAGE_UNSPECIFIED);
}

int FindDrawing(const v1::Session& session, uint32_t drawing_id) {
  for (int i = 0; i < session.drawings_size(); ++i) {
    if (session.drawings(i).id() == drawing_id) return i;
  }
  return -1;
}

absl::Status CheckName(const std::string& name, absl::string_view field) {
  if (name.size() > kMaxNameBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, " is ", name.size(), " bytes, the limit is ", kMaxNameBytes));
  }
  return absl::OkStatus();
}

// Session ids chosen by clients (ImportSession) follow the same rules as generated ones.
absl::Status CheckSessionIdSyntax(const std::string& id) {
  const bool ok = id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
                    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                           (c >= '0' && c <= '9') || c == '-' || c == '_';
                  });
  if (ok) return absl::OkStatus();
  return absl::InvalidArgumentError("session_id must be at most 64 characters of [A-Za-z0-9_-]");
}

absl::Status CheckCorrespondences(
    const google::protobuf::RepeatedPtrField<v1::Correspondence>& correspondences, int num_drawings,
    absl::string_view field) {
  if (!correspondences.empty() && num_drawings < 2) {
    return absl::FailedPreconditionError(absl::StrCat(
        field, ": correspondences need at least 2 drawings, the session has ", num_drawings));
  }
  for (int i = 0; i < correspondences.size(); ++i) {
    const v1::Correspondence& c = correspondences[i];
    if (c.points_size() != num_drawings) {
      return absl::InvalidArgumentError(absl::StrCat(field, "[", i, "] has ", c.points_size(),
                                                     " points, expected one per drawing (",
                                                     num_drawings, ")"));
    }
    for (int j = 0; j < c.points_size(); ++j) {
      const v1::Point& p = c.points(j);
      if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || std::abs(p.x()) > kMaxCoordinate ||
          std::abs(p.y()) > kMaxCoordinate) {
        return absl::InvalidArgumentError(absl::StrCat(
            field, "[", i, "].points[", j, "] is not finite or exceeds |coordinate| <= 1e9"));
      }
    }
  }
  return absl::OkStatus();
}

v1::MultimeshStats StatsOf(const solver::Multimesh& mesh) {
  v1::MultimeshStats stats;
  stats.set_vertices(mesh.num_vertices());
  stats.set_triangles(static_cast<uint32_t>(mesh.triangles.size()));
  stats.set_shapes(mesh.num_shapes());
  int inverted = 0;
  for (const solver::Points& shape : mesh.shapes) {
    inverted += solver::CountInverted(mesh.triangles, shape);
  }
  stats.set_inverted_triangles(inverted);
  // map_energy and mesh_energy are filled in by the comesh stage (not in this version).
  return stats;
}

// The status to return once the token tripped: the deadline's, or the client's cancellation.
absl::Status StoppedStatus(const grpc::ServerContext& context, absl::string_view rpc) {
  if (context.deadline() <= std::chrono::system_clock::now()) {
    return absl::DeadlineExceededError(absl::StrCat(rpc, " stopped: the deadline passed"));
  }
  return absl::CancelledError(absl::StrCat(rpc, " stopped: the client cancelled or went away"));
}

}  // namespace

InbetweenService::InbetweenService(std::shared_ptr<SessionStore> store)
    : store_(std::move(store)) {}

// ---------------------------------------------------------------------------------------------
// Sessions

grpc::Status InbetweenService::CreateSession(grpc::ServerContext*,
                                             const v1::CreateSessionRequest* request,
                                             v1::CreateSessionResponse* response) {
  std::string session_id;
  return RunRpc("CreateSession", session_id, [&]() -> absl::Status {
    if (auto s = CheckName(request->display_name(), "display_name"); !s.ok()) return s;
    if (auto s = ValidateParameters(request->parameters(), "parameters"); !s.ok()) return s;
    SessionState state;
    state.session.set_display_name(request->display_name());
    *state.session.mutable_parameters() = request->parameters();
    state.session.set_stage(v1::STAGE_UNSPECIFIED);
    absl::StatusOr<SessionState> stored = store_->Create(std::move(state));
    if (!stored.ok()) return stored.status();
    session_id = stored->session.id();
    *response->mutable_session() = stored->session;
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::GetSession(grpc::ServerContext*,
                                          const v1::GetSessionRequest* request,
                                          v1::GetSessionResponse* response) {
  return RunRpc("GetSession", request->session_id(), [&]() -> absl::Status {
    absl::StatusOr<SessionState> state = Load(*store_, request->session_id());
    if (!state.ok()) return state.status();
    if (request->full()) {
      *response->mutable_session() = state->session;
      if (state->multimesh) *response->mutable_multimesh() = ToProto(*state->multimesh);
    } else {
      *response->mutable_session() = Compact(state->session);
    }
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::ListSessions(grpc::ServerContext*,
                                            const v1::ListSessionsRequest* request,
                                            v1::ListSessionsResponse* response) {
  return RunRpc("ListSessions", "", [&]() -> absl::Status {
    // Page sizes above the maximum are clamped (AIP-158), not rejected.
    const uint32_t page_size =
        request->page_size() == 0 ? kDefaultPageSize : std::min(request->page_size(), kMaxPageSize);
    absl::StatusOr<SessionPage> page = store_->List(page_size, request->page_token());
    if (!page.ok()) return page.status();
    for (const SessionState& state : page->sessions) {
      *response->add_sessions() = Summary(state.session);
    }
    response->set_next_page_token(page->next_page_token);
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::DeleteSession(grpc::ServerContext*,
                                             const v1::DeleteSessionRequest* request,
                                             v1::DeleteSessionResponse*) {
  return RunRpc("DeleteSession", request->session_id(), [&]() -> absl::Status {
    if (auto s = RequireSessionId(request->session_id()); !s.ok()) return s;
    return store_->Delete(request->session_id(), request->expected_version());
  });
}

grpc::Status InbetweenService::ExportSession(grpc::ServerContext*,
                                             const v1::ExportSessionRequest* request,
                                             v1::ExportSessionResponse* response) {
  return RunRpc("ExportSession", request->session_id(), [&]() -> absl::Status {
    absl::StatusOr<SessionState> state = Load(*store_, request->session_id());
    if (!state.ok()) return state.status();
    v1::SessionArchive archive;
    archive.set_format_version(1);
    *archive.mutable_session() = state->session;
    if (state->multimesh) *archive.mutable_multimesh() = ToProto(*state->multimesh);
    if (!archive.SerializeToString(response->mutable_data())) {
      return absl::InternalError("could not serialize the session archive");
    }
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::ImportSession(grpc::ServerContext*,
                                             const v1::ImportSessionRequest* request,
                                             v1::ImportSessionResponse* response) {
  std::string session_id = request->session_id();
  return RunRpc("ImportSession", session_id, [&]() -> absl::Status {
    if (auto s = CheckSessionIdSyntax(request->session_id()); !s.ok()) return s;
    v1::SessionArchive archive;
    if (request->data().empty() || !archive.ParseFromString(request->data())) {
      return absl::InvalidArgumentError(
          "data is not a serialized SessionArchive (use the bytes from ExportSession)");
    }
    if (archive.format_version() != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("data: SessionArchive.format_version = ", archive.format_version(),
                       " is not supported (expected 1)"));
    }
    // An archive is untrusted input: everything is checked as if it arrived field by field.
    SessionState state;
    state.session = std::move(*archive.mutable_session());
    state.session.set_id(request->session_id());
    v1::Session& session = state.session;
    if (auto s = CheckName(session.display_name(), "data: session.display_name"); !s.ok()) {
      return s;
    }
    if (auto s = ValidateParameters(session.parameters(), "data: session.parameters"); !s.ok()) {
      return s;
    }
    if (session.drawings_size() > kMaxDrawingsPerSession) {
      return absl::ResourceExhaustedError(
          absl::StrCat("data: the session has ", session.drawings_size(),
                       " drawings, the limit is ", kMaxDrawingsPerSession));
    }
    uint32_t max_id = 0;
    for (int i = 0; i < session.drawings_size(); ++i) {
      v1::Drawing& drawing = *session.mutable_drawings(i);
      const std::string field = absl::StrCat("data: session.drawings[", i, "]");
      if (drawing.id() == 0 || FindDrawing(session, drawing.id()) != i) {
        return absl::InvalidArgumentError(
            absl::StrCat(field, ".id = ", drawing.id(), " is zero or not unique"));
      }
      max_id = std::max(max_id, drawing.id());
      absl::StatusOr<ImportedDrawing> imported =
          drawing.elements().empty() ? ImportDrawing(drawing, kDefaultFlattenTolerance, field)
                                     : ImportDrawingElements(drawing, field);
      if (!imported.ok()) return imported.status();
      if (drawing.elements().empty()) *drawing.mutable_elements() = imported->elements;
      state.parsed.push_back(std::move(imported->parsed));
    }
    state.next_drawing_id = max_id + 1;
    if (auto s = CheckCorrespondences(session.correspondences(), session.drawings_size(),
                                      "data: session.correspondences");
        !s.ok()) {
      return s;
    }
    if (archive.has_multimesh() && archive.multimesh().shapes_size() > 0) {
      absl::StatusOr<solver::Multimesh> mesh =
          MultimeshFromProto(archive.multimesh(), "data: multimesh");
      if (!mesh.ok()) return mesh.status();
      if (mesh->num_shapes() != session.drawings_size()) {
        return absl::InvalidArgumentError(absl::StrCat("data: multimesh has ", mesh->num_shapes(),
                                                       " shapes for ", session.drawings_size(),
                                                       " drawings"));
      }
      if (auto s = solver::ValidateMultimesh(*mesh); !s.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("data: multimesh: ", s.message()));
      }
      v1::MultimeshStats stats = StatsOf(*mesh);
      stats.set_map_energy(session.multimesh_stats().map_energy());
      stats.set_mesh_energy(session.multimesh_stats().mesh_energy());
      stats.set_build_seconds(session.multimesh_stats().build_seconds());
      *session.mutable_multimesh_stats() = stats;
      session.set_stage(std::max(session.stage(), v1::STAGE_MULTIMESH));
      state.multimesh = std::make_shared<const solver::Multimesh>(*std::move(mesh));
    } else {
      InvalidateMultimesh(state);
    }
    absl::StatusOr<SessionState> stored = store_->Create(std::move(state));
    if (!stored.ok()) return stored.status();
    session_id = stored->session.id();
    *response->mutable_session() = Compact(stored->session);
    return absl::OkStatus();
  });
}

// ---------------------------------------------------------------------------------------------
// Drawings and topology

grpc::Status InbetweenService::PutDrawing(grpc::ServerContext*,
                                          const v1::PutDrawingRequest* request,
                                          v1::PutDrawingResponse* response) {
  return RunRpc("PutDrawing", request->session_id(), [&]() -> absl::Status {
    absl::StatusOr<SessionState> state =
        LoadForUpdate(*store_, request->session_id(), request->expected_version());
    if (!state.ok()) return state.status();
    if (request->topology_size() > 0) {
      // The contract says: refuse rather than silently drop the cuts/openings.
      return absl::UnimplementedError(
          "PutDrawing.topology (cuts and openings) is not implemented yet in this server version");
    }
    // SVG parsing runs here, outside the store's lock.
    absl::StatusOr<ImportedDrawing> imported =
        ImportDrawing(request->drawing(), request->flatten_tolerance(), "drawing");
    if (!imported.ok()) return imported.status();

    v1::Session& session = state->session;
    v1::Drawing drawing = request->drawing();
    *drawing.mutable_elements() = imported->elements;
    int index = -1;
    if (drawing.id() == 0) {
      if (session.drawings_size() >= kMaxDrawingsPerSession) {
        return absl::ResourceExhaustedError(absl::StrCat("session ", session.id(),
                                                         " already has the maximum of ",
                                                         kMaxDrawingsPerSession, " drawings"));
      }
      drawing.set_id(state->next_drawing_id++);
      *session.add_drawings() = drawing;
      state->parsed.push_back(std::move(imported->parsed));
      index = session.drawings_size() - 1;
      // Each mark has one point per drawing; with a new drawing the old marks no longer fit.
      session.clear_correspondences();
    } else {
      index = FindDrawing(session, drawing.id());
      if (index < 0) {
        return absl::NotFoundError(
            absl::StrCat("drawing ", drawing.id(), " not found in session ", session.id()));
      }
      *session.mutable_drawings(index) = drawing;
      state->parsed[index] = std::move(imported->parsed);
    }
    InvalidateMultimesh(*state);
    absl::StatusOr<SessionState> stored =
        store_->Put(*std::move(state), request->expected_version());
    if (!stored.ok()) return stored.status();
    *response->mutable_session() = Compact(stored->session);
    *response->mutable_drawing() = stored->session.drawings(index);
    response->mutable_drawing()->clear_source();
    *response->mutable_equivalence_class() = imported->equivalence_class;
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::RemoveDrawing(grpc::ServerContext*,
                                             const v1::RemoveDrawingRequest* request,
                                             v1::RemoveDrawingResponse* response) {
  return RunRpc("RemoveDrawing", request->session_id(), [&]() -> absl::Status {
    absl::StatusOr<SessionState> state =
        LoadForUpdate(*store_, request->session_id(), request->expected_version());
    if (!state.ok()) return state.status();
    const int index = FindDrawing(state->session, request->drawing_id());
    if (request->drawing_id() == 0 || index < 0) {
      return absl::NotFoundError(absl::StrCat("drawing ", request->drawing_id(),
                                              " not found in session ", request->session_id()));
    }
    state->session.mutable_drawings()->DeleteSubrange(index, 1);
    state->parsed.erase(state->parsed.begin() + index);
    state->session.clear_correspondences();  // one point per drawing; they no longer fit
    InvalidateMultimesh(*state);
    absl::StatusOr<SessionState> stored =
        store_->Put(*std::move(state), request->expected_version());
    if (!stored.ok()) return stored.status();
    *response->mutable_session() = Compact(stored->session);
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::EditTopology(
    grpc::ServerContext*, grpc::ServerReaderWriter<v1::TopologyState, v1::TopologyEdit>*) {
  return NotImplemented("EditTopology", "");
}

grpc::Status InbetweenService::SetCorrespondences(grpc::ServerContext*,
                                                  const v1::SetCorrespondencesRequest* request,
                                                  v1::SetCorrespondencesResponse* response) {
  return RunRpc("SetCorrespondences", request->session_id(), [&]() -> absl::Status {
    absl::StatusOr<SessionState> state =
        LoadForUpdate(*store_, request->session_id(), request->expected_version());
    if (!state.ok()) return state.status();
    if (auto s = CheckCorrespondences(request->correspondences(), state->session.drawings_size(),
                                      "correspondences");
        !s.ok()) {
      return s;
    }
    // Stored only: the slice's BuildMultimesh matches boundaries automatically and does not read
    // the marks yet. They still invalidate the multimesh, because once the solver uses them a
    // mesh built without them would be stale.
    *state->session.mutable_correspondences() = request->correspondences();
    InvalidateMultimesh(*state);
    absl::StatusOr<SessionState> stored =
        store_->Put(*std::move(state), request->expected_version());
    if (!stored.ok()) return stored.status();
    *response->mutable_session() = Compact(stored->session);
    return absl::OkStatus();
  });
}

// ---------------------------------------------------------------------------------------------
// Heavy stages

grpc::Status InbetweenService::BuildMultimesh(
    grpc::ServerContext* context, const v1::BuildMultimeshRequest* request,
    grpc::ServerWriter<v1::BuildMultimeshResponse>* writer) {
  return RunRpc("BuildMultimesh", request->session_id(), [&]() -> absl::Status {
    absl::StatusOr<SessionState> state =
        LoadForUpdate(*store_, request->session_id(), request->expected_version());
    if (!state.ok()) return state.status();
    if (state->session.drawings_size() < 2) {
      return absl::FailedPreconditionError(
          absl::StrCat("BuildMultimesh needs at least 2 drawings, session ", request->session_id(),
                       " has ", state->session.drawings_size()));
    }
    const bool own_meshing = request->has_meshing();
    const v1::MeshingParameters& meshing =
        own_meshing ? request->meshing() : state->session.parameters().meshing();
    if (auto s = ValidateMeshing(meshing, own_meshing ? "meshing" : "session parameters.meshing");
        !s.ok()) {
      return s;
    }

    solver::CancelToken token;
    CancelWatcher watcher(context, &token);
    std::mutex write_mutex;  // in case the solver reports progress from worker threads
    solver::ProgressFn progress = [&](const std::string& stage, double fraction,
                                      const std::string& detail) {
      if (context->IsCancelled()) {
        token.Cancel();
        return;
      }
      v1::BuildMultimeshResponse message;
      v1::Progress* p = message.mutable_progress();
      p->set_stage(stage);
      p->set_fraction(std::clamp(fraction, 0.0, 1.0));
      p->set_detail(detail);
      std::lock_guard lock(write_mutex);
      if (!writer->Write(message)) token.Cancel();
    };
    const Clock::time_point start = Clock::now();
    solver::MultimeshReport report;
    absl::StatusOr<solver::Multimesh> mesh = solver::BuildMultimesh(
        state->parsed, ToMultimeshOptions(meshing), &token, progress, &report);
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (token.IsCancelled() || context->IsCancelled()) {
      return StoppedStatus(*context, "BuildMultimesh");
    }
    if (!mesh.ok()) return mesh.status();
    // The solver promises a valid mesh; a stored multimesh is never silently flipped.
    if (mesh->num_shapes() != state->session.drawings_size()) {
      return absl::InternalError(absl::StrCat("the multimesh builder returned ", mesh->num_shapes(),
                                              " shapes for ", state->session.drawings_size(),
                                              " drawings"));
    }
    if (absl::Status s = solver::ValidateMultimesh(*mesh); !s.ok()) {
      return absl::InternalError(
          absl::StrCat("the multimesh builder returned an invalid mesh: ", s.message()));
    }
    v1::MultimeshStats stats = StatsOf(*mesh);
    stats.set_build_seconds(report.seconds > 0 ? report.seconds : seconds);

    v1::BuildMultimeshResponse message;
    v1::BuildMultimeshResult* result = message.mutable_result();
    *result->mutable_multimesh() = ToProto(*mesh);
    state->multimesh = std::make_shared<const solver::Multimesh>(*std::move(mesh));
    state->session.set_stage(v1::STAGE_MULTIMESH);
    *state->session.mutable_multimesh_stats() = stats;
    absl::StatusOr<SessionState> stored =
        store_->Put(*std::move(state), request->expected_version());
    if (!stored.ok()) return stored.status();
    *result->mutable_session() = Compact(stored->session);
    *result->mutable_stats() = stats;
    std::lock_guard lock(write_mutex);
    if (!writer->Write(message)) return StoppedStatus(*context, "BuildMultimesh");
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::OptimizeComesh(grpc::ServerContext*,
                                              const v1::OptimizeComeshRequest* request,
                                              grpc::ServerWriter<v1::OptimizeComeshResponse>*) {
  return NotImplemented("OptimizeComesh", request->session_id());
}

grpc::Status InbetweenService::Inbetween(grpc::ServerContext* context,
                                         const v1::InbetweenRequest* request,
                                         grpc::ServerWriter<v1::InbetweenResponse>* writer) {
  return RunRpc("Inbetween", request->session_id(), [&]() -> absl::Status {
    absl::StatusOr<SessionState> state = Load(*store_, request->session_id());
    if (!state.ok()) return state.status();
    const v1::Session& session = state->session;
    if (session.stage() < v1::STAGE_MULTIMESH || !state->multimesh) {
      return absl::FailedPreconditionError(
          absl::StrCat("session ", session.id(),
                       " has no multimesh: build the multimesh first (BuildMultimesh)"));
    }
    const solver::Multimesh& mesh = *state->multimesh;
    const v1::InbetweenParameters parameters =
        MergeInbetween(session.parameters().inbetween(), request->parameters());
    absl::StatusOr<InbetweenPlan> plan = ToInbetweenPlan(parameters, "parameters");
    if (!plan.ok()) return plan.status();
    plan->options.stiffness = StiffnessPerTriangle(mesh, parameters.stiffness());
    const int num_drawings = session.drawings_size();
    if (plan->frames < num_drawings) {
      return absl::InvalidArgumentError(absl::StrCat("parameters.frames = ", plan->frames,
                                                     " is fewer than the ", num_drawings,
                                                     " drawings (every drawing is a key frame)"));
    }
    if (request->start_frame() >= static_cast<uint32_t>(plan->frames)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "start_frame = ", request->start_frame(), " is not in [0, frames = ", plan->frames, ")"));
    }
    // Key times come from the drawings when every drawing has one, else keys are evenly spaced.
    std::vector<double> key_times;
    for (const v1::Drawing& drawing : session.drawings()) {
      if (drawing.has_key_time()) key_times.push_back(drawing.key_time());
    }
    if (!key_times.empty() && static_cast<int>(key_times.size()) != num_drawings) {
      return absl::InvalidArgumentError(
          absl::StrCat("key_time is set on ", key_times.size(), " of ", num_drawings,
                       " drawings: set it on every drawing or on none"));
    }
    absl::StatusOr<solver::Schedule> schedule =
        solver::MakeSchedule(num_drawings, plan->frames, key_times);
    if (!schedule.ok()) {
      return absl::Status(
          schedule.status().code(),
          absl::StrCat(key_times.empty() ? "frame schedule: " : "drawings' key_time: ",
                       schedule.status().message()));
    }

    solver::CancelToken token;
    CancelWatcher watcher(context, &token);
    absl::StatusOr<solver::Inbetweener> inbetweener =
        solver::Inbetweener::Create(mesh, plan->options);
    if (!inbetweener.ok()) return inbetweener.status();

    v1::InbetweenResponse message;
    v1::InbetweenHeader* header = message.mutable_header();
    for (const solver::Triangle& t : mesh.triangles) {
      v1::Triangle* triangle = header->add_triangles();
      triangle->set_a(t[0]);
      triangle->set_b(t[1]);
      triangle->set_c(t[2]);
    }
    for (int key : schedule->keys) header->add_keys(key);
    header->set_frames(plan->frames);
    header->set_session_version(session.version());
    if (!writer->Write(message)) return StoppedStatus(*context, "Inbetween");

    // Frames before start_frame are solved but not sent: each frame warm-starts from the
    // previous one, so a resumed stream must replay them to stay identical.
    solver::Frame previous;
    for (int i = 0; i < plan->frames; ++i) {
      if (token.IsCancelled()) return StoppedStatus(*context, "Inbetween");
      const solver::FrameTiming& timing = schedule->frames[i];
      solver::FrameReport report;
      const Clock::time_point start = Clock::now();
      absl::StatusOr<solver::Frame> frame =
          inbetweener->Solve(timing.weights, previous, &token, &report);
      const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
      if (token.IsCancelled()) return StoppedStatus(*context, "Inbetween");
      if (!frame.ok()) {
        return absl::Status(frame.status().code(),
                            absl::StrCat("frame ", i, ": ", frame.status().message()));
      }
      if (static_cast<int>(frame->vertices.size()) != mesh.num_vertices()) {
        return absl::InternalError(absl::StrCat("frame ", i, " has ", frame->vertices.size(),
                                                " vertices, the mesh has ", mesh.num_vertices()));
      }
      if (i >= static_cast<int>(request->start_frame())) {
        message.Clear();
        v1::InbetweenFrame* out = message.mutable_frame();
        out->set_index(i);
        out->set_time(timing.time);
        for (double w : timing.weights) out->add_weights(w);
        ToProto(frame->vertices, out->mutable_vertices());
        v1::FrameStats* stats = out->mutable_stats();
        stats->set_iterations(report.iterations);
        stats->set_energy(report.energy);
        stats->set_inverted_triangles(solver::CountInverted(mesh.triangles, frame->vertices));
        stats->set_seconds(report.seconds > 0 ? report.seconds : seconds);
        if (!writer->Write(message)) return StoppedStatus(*context, "Inbetween");
      }
      previous = *std::move(frame);
    }
    return absl::OkStatus();
  });
}

}  // namespace inbetween::server
