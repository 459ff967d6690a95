// inbetween.v1.Inbetween handlers. Each one: validate -> session store / solver -> status.
// Sessions are copied out of the store, worked on unlocked, and put back with the version they
// were read at, so a concurrent mutation makes the later writer fail with ABORTED.
#include "server/inbetween_service.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <new>
#include <optional>
#include <random>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/cancel_watcher.h"
#include "server/comesh_progress.h"
#include "server/drawing_import.h"
#include "server/logging.h"
#include "server/parameters.h"
#include "server/proto_convert.h"
#include "server/session_snapshot.h"
#include "server/status_mapping.h"
#include "server/stiffness_field.h"
#include "solver/art/art_embedding.h"
#include "solver/comesh/comesh_objective.h"
#include "solver/comesh/comesh_optimizer.h"
#include "solver/core/error_reason.h"
#include "solver/geometry/graph_flow.h"
#include "solver/interp/inbetweener.h"
#include "solver/interp/timing.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"

namespace inbetween::server {
namespace {

namespace v1 = ::inbetween::v1;
using Clock = std::chrono::steady_clock;

// Who is calling: the request id of this call and the owner its token maps to ("" without
// --tokens).
struct Caller {
  std::string request_id;
  std::string owner;
};

// The client's x-request-id (if short and printable) or a new one: process prefix + counter.
std::string RequestId(const grpc::ServerContext& context) {
  auto it = context.client_metadata().find("x-request-id");
  if (it != context.client_metadata().end() && !it->second.empty() && it->second.size() <= 64 &&
      std::all_of(it->second.begin(), it->second.end(),
                  [](char c) { return c > ' ' && c < 127 && c != '"' && c != '\\'; })) {
    return std::string(it->second.data(), it->second.size());
  }
  static const std::string prefix = [] {
    std::mt19937_64 rng(std::random_device{}());
    return RandomSessionId(rng).substr(0, 8);
  }();
  static std::atomic<uint64_t> counter{0};
  return absl::StrCat(prefix, "-", ++counter);
}

// Runs a handler body: names the request, authenticates the caller (with --tokens), catches
// anything thrown (a bug must not take the server down), maps the status once, logs one line and
// counts it. `session_id` is read after `body` ran (CreateSession sets it).
template <typename Body>
grpc::Status RunRpcUnguarded(const ServiceOptions& options, grpc::ServerContext* context,
                             absl::string_view rpc, const std::string& session_id, Caller* caller,
                             Body&& body) {
  const Clock::time_point start = Clock::now();
  caller->request_id = RequestId(*context);
  context->AddInitialMetadata("x-request-id", caller->request_id);
  absl::Status status;
  if (options.tokens) {
    absl::StatusOr<std::string> owner = options.tokens->Authenticate(*context);
    if (owner.ok()) {
      caller->owner = *std::move(owner);
    } else {
      status = owner.status();
    }
  }
  if (status.ok()) {
    try {
      status = body();
    } catch (const std::bad_alloc&) {
      // Out of memory (e.g. under an address-space cap) is not a bug: RESOURCE_EXHAUSTED, like
      // the solver's own allocation failures ("mapping drawing k ...: out of memory ...").
      status = absl::ResourceExhaustedError(
          absl::StrCat(rpc, ": the server ran out of memory; try again later or a smaller job"));
    } catch (const std::system_error& e) {
      // EAGAIN from std::thread: no memory (or no thread) left for a worker's stack.
      status =
          e.code() == std::errc::resource_unavailable_try_again
              ? absl::ResourceExhaustedError(absl::StrCat(
                    rpc, ": the server could not start a thread (", e.what(), "); try again later"))
              : absl::InternalError(absl::StrCat(rpc, " failed: ", e.what()));
    } catch (const std::exception& e) {
      status = absl::InternalError(absl::StrCat(rpc, " failed: ", e.what()));
    } catch (...) {
      status = absl::InternalError(absl::StrCat(rpc, " failed with an unknown exception"));
    }
  }
  grpc::Status out = ToGrpcStatus(status);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  LogRpc(caller->request_id, rpc, session_id, out, seconds, options.log_ok_rpcs_at_info);
  if (options.metrics) {
    options.metrics->ObserveRpc(rpc, absl::StatusCodeToString(status.code()), seconds);
  }
  return out;
}

// RunRpcUnguarded, and if even that throws (out of memory while wording an error, logging or
// counting it: seen under an address-space cap), an answer that allocates nothing (a message
// short enough for std::string's inline buffer). Escaping, the exception would reach gRPC's own
// catch, whose message allocation fails again and terminates the process.
template <typename Body>
grpc::Status RunRpc(const ServiceOptions& options, grpc::ServerContext* context,
                    absl::string_view rpc, const std::string& session_id, Caller* caller,
                    Body&& body) {
  try {
    return RunRpcUnguarded(options, context, rpc, session_id, caller, std::forward<Body>(body));
  } catch (const std::bad_alloc&) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, "out of memory");
  } catch (...) {
    return grpc::Status(grpc::StatusCode::INTERNAL, "internal error");
  }
}

absl::Status RequireSessionId(const std::string& id) {
  if (id.empty()) return absl::InvalidArgumentError("session_id is required");
  return absl::OkStatus();
}

// Another owner's session is NOT_FOUND, worded exactly like a missing one (no existence leak).
// `latest`: past replicas' caches (SessionStore::GetLatest), for a stored comesh checkpoint.
absl::StatusOr<SessionState> Load(const SessionStore& store, const std::string& id,
                                  const Caller& caller, bool latest = false) {
  if (absl::Status s = RequireSessionId(id); !s.ok()) return s;
  absl::StatusOr<SessionState> state = latest ? store.GetLatest(id) : store.Get(id);
  if (state.ok() && state->owner != caller.owner) return SessionNotFoundError(id);
  return state;
}

// Load for a mutation: also checks expected_version against the current version.
absl::StatusOr<SessionState> LoadForUpdate(const SessionStore& store, const std::string& id,
                                           uint64_t expected_version, const Caller& caller,
                                           bool latest = false) {
  absl::StatusOr<SessionState> state = Load(store, id, caller, latest);
  if (!state.ok()) return state.status();
  if (state->session.version() != expected_version) {
    return StaleVersionError(id, state->session.version(), expected_version);
  }
  return state;
}

// The session without drawing sources and art (both can be large); elements stay.
v1::Session Compact(const v1::Session& session) {
  v1::Session out = session;
  for (v1::Drawing& drawing : *out.mutable_drawings()) {
    drawing.clear_source();
    drawing.clear_art();
  }
  return out;
}

// The header's art and the InbetweenResponse.art messages that carry what does not fit in it
// (InbetweenHeader.art_messages): every message stays under kArtMessageBytes, so a client with
// gRPC's default 4 MiB receive limit reads a stream whose art is far larger. The art is the
// stored multimesh's (embedded by BuildMultimesh and again after OptimizeComesh).
constexpr size_t kArtMessageBytes = 1 << 20;

// Frame `index` of an Inbetween stream as sent: its time, key weights, vertices and stats
// (`seconds`: the caller's timing, when the solver's report has none).
v1::InbetweenFrame FrameMessage(int index, const solver::FrameTiming& timing,
                                const solver::Frame& frame, const solver::FrameReport& report,
                                double seconds) {
  v1::InbetweenFrame out;
  out.set_index(index);
  out.set_time(timing.time);
  for (double w : timing.weights) out.add_weights(w);
  ToProto(frame.vertices, out.mutable_vertices());
  v1::FrameStats* stats = out.mutable_stats();
  stats->set_iterations(report.iterations);
  stats->set_energy(report.energy);
  stats->set_inverted_triangles(report.inverted);
  stats->set_boundary_overlaps(report.overlaps);
  stats->set_min_area_ratio(report.min_area_ratio);
  stats->set_max_area_ratio(report.max_area_ratio);
  stats->set_separated_cohesive_edges(report.separated_edges);
  stats->set_overlap_hold_back(report.hold_back);
  stats->set_seconds(report.seconds > 0 ? report.seconds : seconds);
  return out;
}

std::vector<v1::InbetweenResponse> AddKeyArt(const solver::Multimesh& mesh,
                                             v1::InbetweenHeader* header) {
  std::vector<v1::InbetweenResponse> more;
  if (mesh.art.empty()) return more;
  // A field's bytes in its message: the payload plus a tag and a length of at most 6 bytes.
  auto field_bytes = [](const google::protobuf::Message& m) { return m.ByteSizeLong() + 6; };
  size_t header_bytes = header->ByteSizeLong();
  bool header_full = false;
  v1::KeyArt* chunk = nullptr;  // the art message being filled
  size_t chunk_bytes = 0;
  for (const solver::EmbeddedArt& art : mesh.art) {
    v1::KeyArt* in_header = header->add_art();
    in_header->set_key(static_cast<uint32_t>(art.key));
    header_bytes += 16;
    chunk = nullptr;  // each key starts its own art message
    for (const solver::EmbeddedLayer& layer : art.layers) {
      v1::EmbeddedArtLayer proto_layer;
      ToProto(layer, &proto_layer);
      const size_t bytes = field_bytes(proto_layer);
      if (!header_full && header_bytes + bytes <= kArtMessageBytes) {
        *in_header->add_layers() = std::move(proto_layer);
        header_bytes += bytes;
        continue;
      }
      header_full = true;  // later layers of every key follow in order, in art messages
      if (chunk == nullptr ||
          (chunk_bytes + bytes > kArtMessageBytes && chunk->layers_size() > 0)) {
        chunk = more.emplace_back().mutable_art();
        chunk->set_key(static_cast<uint32_t>(art.key));
        chunk_bytes = 16;
      }
      *chunk->add_layers() = std::move(proto_layer);
      chunk_bytes += bytes;
    }
  }
  header->set_art_messages(static_cast<uint32_t>(more.size()));
  return more;
}

// Any change to drawings or correspondences drops the multimesh built from them.
void InvalidateMultimesh(SessionState& state) {
  state.multimesh.reset();
  state.comesh_checkpoint.reset();
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
  stats.set_worst_quality(mesh.triangles.empty() ? 0.0 : solver::WorstQuality(mesh));
  // The comesh objective's reported energies (2 = conformal maps, 1 = equilateral tiling), with
  // the mesh itself as the rest state; left 0 for a mesh it cannot evaluate (one shape).
  if (mesh.num_shapes() >= 2 && inverted == 0) {
    absl::StatusOr<solver::ComeshObjective> objective =
        solver::ComeshObjective::Create(mesh.triangles, mesh.shapes);
    if (objective.ok()) {
      solver::ComeshEnergies energies;
      objective->Evaluate(mesh.shapes, nullptr, &energies);
      if (std::isfinite(energies.map) && std::isfinite(energies.mesh)) {
        stats.set_map_energy(energies.map);
        stats.set_mesh_energy(energies.mesh);
      }
    }
  }
  return stats;
}

// What only the build knew (its time, the loops it matched corner to corner), kept from the
// build's stats into those of a later mesh of the same session (optimized or imported).
void KeepBuildFacts(const v1::MultimeshStats& build, v1::MultimeshStats* stats) {
  stats->set_build_seconds(build.build_seconds());
  stats->set_corner_matched_loops(build.corner_matched_loops());
  stats->set_overlays(build.overlays());
  stats->set_achieved_tolerance(build.achieved_tolerance());
}

// The status to return once the token tripped: the deadline's, or the client's cancellation.
absl::Status StoppedStatus(const grpc::ServerContext& context, absl::string_view rpc) {
  if (context.deadline() <= std::chrono::system_clock::now()) {
    return absl::DeadlineExceededError(absl::StrCat(rpc, " stopped: the deadline passed"));
  }
  return absl::CancelledError(absl::StrCat(rpc, " stopped: the client cancelled or went away"));
}

int FindElement(const v1::Drawing& drawing, uint32_t element_id) {
  for (int i = 0; i < drawing.elements_size(); ++i) {
    if (drawing.elements(i).id() == element_id) return i;
  }
  return -1;
}

absl::string_view KindName(v1::ElementKind kind) {
  switch (kind) {
    case v1::ELEMENT_KIND_OUTLINE:
      return "outline";
    case v1::ELEMENT_KIND_CUT:
      return "cut";
    case v1::ELEMENT_KIND_OPENING:
      return "opening";
    default:
      return "element";
  }
}

// Applies the add, move or delete of `edit` (number n of the stream) to the elements of
// `drawing` (number index + 1 of the session) and returns what was done, for messages ("edit 0
// (move cut 3) in drawing 2 'mouth.svg'"); a bad edit is INVALID_ARGUMENT naming the edit and
// the element.
absl::StatusOr<std::string> EditElements(const v1::TopologyEdit& edit, int n, int index,
                                         v1::Drawing& drawing) {
  std::string what;
  auto named = [&](absl::string_view verb, v1::ElementKind kind, uint32_t id) {
    return absl::StrCat("edit ", n, " (", verb, " ", KindName(kind), " ", id, ") in drawing ",
                        index + 1, drawing.name().empty() ? "" : " '", drawing.name(),
                        drawing.name().empty() ? "" : "'");
  };
  switch (edit.edit_case()) {
    case v1::TopologyEdit::kAdd: {
      const v1::TopologyElement& element = edit.add();
      if (element.id() != 0) {
        return absl::InvalidArgumentError(absl::StrCat("edit ", n, ": add.id = ", element.id(),
                                                       " must be 0 (the server assigns ids)"));
      }
      uint32_t id = 0;
      for (const v1::TopologyElement& e : drawing.elements()) id = std::max(id, e.id());
      ++id;
      what = named("add", element.kind(), id);
      v1::TopologyElement* added = drawing.add_elements();
      *added = element;
      added->set_id(id);
      break;
    }
    case v1::TopologyEdit::kMove: {
      const v1::TopologyElement& element = edit.move();
      const int i = FindElement(drawing, element.id());
      if (element.id() == 0 || i < 0) {
        return absl::InvalidArgumentError(absl::StrCat("edit ", n, ": move.id = ", element.id(),
                                                       " is not an element of drawing ",
                                                       edit.drawing_id()));
      }
      v1::TopologyElement& target = *drawing.mutable_elements(i);
      if (element.kind() != v1::ELEMENT_KIND_UNSPECIFIED && element.kind() != target.kind()) {
        return absl::InvalidArgumentError(absl::StrCat(
            "edit ", n, ": move.kind = ", v1::ElementKind_Name(element.kind()), " but element ",
            element.id(), " is a ", KindName(target.kind()), " (delete and add to change it)"));
      }
      what = named("move", target.kind(), element.id());
      *target.mutable_polyline() = element.polyline();
      break;
    }
    case v1::TopologyEdit::kDeleteElement: {
      const int i = FindElement(drawing, edit.delete_element());
      if (edit.delete_element() == 0 || i < 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("edit ", n, ": delete_element = ", edit.delete_element(),
                         " is not an element of drawing ", edit.drawing_id()));
      }
      what = named("delete", drawing.elements(i).kind(), edit.delete_element());
      drawing.mutable_elements()->DeleteSubrange(i, 1);
      break;
    }
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("edit ", n, ": set one of add, move or delete_element"));
  }
  return what;
}

// The TopologyState reply after an edit of drawing number index + 1, without its version: the
// drawing's elements, boundaries and cohesive edges, every drawing's class (`imported`'s for the
// edited one), and a warning for each drawing whose class differs from the edited one's.
v1::TopologyState TopologyReply(const SessionState& state, int index,
                                const ImportedDrawing& imported) {
  const v1::Session& session = state.session;
  const v1::Drawing& drawing = session.drawings(index);
  v1::TopologyState reply;
  reply.set_drawing_id(drawing.id());
  *reply.mutable_elements() = drawing.elements();
  const solver::BoundaryGraph& graph = imported.boundaries;
  for (size_t l = 0; l < graph.loops.size(); ++l) {
    const solver::BoundaryLoop& loop = graph.loops[l];
    ToProto(loop.points, reply.add_boundaries()->mutable_points());
    for (size_t k = 0; k < loop.twin.size(); ++k) {
      // One CohesiveEdge per pair: emitted from the side that comes first.
      const auto [twin_loop, twin_edge] = loop.twin[k];
      if (twin_loop < 0 || std::pair<int, int>(twin_loop, twin_edge) <
                               std::pair<int, int>(static_cast<int>(l), static_cast<int>(k))) {
        continue;
      }
      v1::CohesiveEdge* edge = reply.add_cohesive_edges();
      ToProto(loop.points[k], edge->mutable_a());
      ToProto(loop.points[(k + 1) % loop.points.size()], edge->mutable_b());
    }
  }
  for (int j = 0; j < session.drawings_size(); ++j) {
    if (j == index) {
      *reply.add_classes() = imported.equivalence_class;
      continue;
    }
    absl::StatusOr<solver::BoundaryGraph> other = solver::BuildBoundaries(state.parsed[j], j + 1);
    if (other.ok()) {
      *reply.add_classes() = ToProto(other->equivalence);
    } else {
      reply.add_classes();
      reply.add_warnings(std::string(other.status().message()));
    }
  }
  for (int j = 0; j < reply.classes_size(); ++j) {
    const v1::EquivalenceClass& a = reply.classes(j);
    const v1::EquivalenceClass& b = reply.classes(index);
    if (j != index && (a.components() != b.components() || a.holes() != b.holes())) {
      reply.add_warnings(absl::StrCat("drawing ", j + 1, " has ", a.components(),
                                      " component(s) and ", a.holes(), " hole(s), drawing ",
                                      index + 1, " has ", b.components(), " and ", b.holes(),
                                      ": the multimesh needs every drawing in the same class"));
    }
  }
  return reply;
}

// Applies one TopologyEdit to `state` (elements, solver drawing, multimesh dropped) and returns
// the reply without its version. A bad edit is INVALID_ARGUMENT naming the edit, the drawing and
// the element.
absl::StatusOr<v1::TopologyState> ApplyTopologyEdit(const v1::TopologyEdit& edit, int n,
                                                    int max_points, SessionState& state) {
  v1::Session& session = state.session;
  const int index = edit.drawing_id() == 0 ? -1 : FindDrawing(session, edit.drawing_id());
  if (index < 0) {
    return absl::NotFoundError(absl::StrCat("edit ", n, ": drawing ", edit.drawing_id(),
                                            " not found in session ", session.id()));
  }
  v1::Drawing& drawing = *session.mutable_drawings(index);
  absl::StatusOr<std::string> what = EditElements(edit, n, index, drawing);
  if (!what.ok()) return what.status();
  absl::StatusOr<ImportedDrawing> imported =
      ImportDrawingElements(drawing, absl::StrCat("drawing ", index + 1), index + 1, max_points);
  if (!imported.ok()) {
    return absl::Status(imported.status().code(),
                        absl::StrCat(*what, ": ", imported.status().message()));
  }
  state.parsed[index] = std::move(imported->parsed);
  InvalidateMultimesh(state);
  return TopologyReply(state, index, *imported);
}

// Comesh options for optimizing `state`'s multimesh with `comesh`. The outline guard holds the
// keys to the session's outline tolerance, measured against the drawings the multimesh was built
// from (without them, e.g. a session whose drawings do not match the mesh's shapes, against the
// mesh's own outline).
solver::ComeshOptions ComeshOptionsFor(const SessionState& state,
                                       const v1::ComeshParameters& comesh) {
  solver::ComeshOptions options = ToComeshOptions(comesh);
  options.outline_tolerance = ComeshOutlineTolerance(state.session.parameters().meshing());
  if (static_cast<int>(state.parsed.size()) == state.multimesh->num_shapes()) {
    for (const solver::Drawing& drawing : state.parsed) {
      std::vector<solver::Points>& loops = options.outline_reference.emplace_back();
      for (const solver::Outline& outline : drawing.outlines) loops.push_back(outline.points);
    }
  }
  return options;
}

// The progress message that opens a resumed optimization.
v1::OptimizeComeshResponse ResumedNotice(const solver::ComeshCheckpoint& from,
                                         uint64_t stored_version) {
  v1::OptimizeComeshResponse message;
  v1::Progress* p = message.mutable_progress();
  p->set_stage("comesh");
  p->set_detail(
      absl::StrFormat("resumed after outer %d at iteration %d (checkpoint of session version %d)",
                      from.outer, from.inner, stored_version));
  return message;
}

// The optimized mesh has new triangles: the drawings' art is embedded in it again, and the mesh
// is checked before it is stored (INTERNAL if the optimizer broke its promise).
absl::Status EmbedArtAndValidate(const std::vector<solver::Drawing>& drawings,
                                 solver::Multimesh* mesh) {
  absl::StatusOr<std::vector<solver::EmbeddedArt>> art = solver::EmbedDrawingsArt(*mesh, drawings);
  if (!art.ok()) return art.status();
  mesh->art = *std::move(art);
  if (absl::Status s = solver::ValidateMultimesh(*mesh); !s.ok()) {
    return absl::InternalError(
        absl::StrCat("the comesh optimizer returned an invalid mesh: ", s.message()));
  }
  return absl::OkStatus();
}

// The checkpoint a resumed OptimizeComesh continues from, or null to start over. Checkpoints are
// written without moving the version (docs/api.md "Resuming OptimizeComesh"): one stored at this
// version is of a run on this multimesh, and it is continued only for the same parameters.
const solver::ComeshCheckpoint* CheckpointToResume(const v1::OptimizeComeshRequest& request,
                                                   const SessionState& state,
                                                   const std::string& parameters_key) {
  const std::shared_ptr<const StoredComeshCheckpoint>& checkpoint = state.comesh_checkpoint;
  const bool own_checkpoint = request.resume() && checkpoint &&
                              checkpoint->input_version == request.expected_version() &&
                              checkpoint->stored_version == state.session.version();
  return own_checkpoint && checkpoint->parameters == parameters_key ? &checkpoint->checkpoint
                                                                    : nullptr;
}

// The result of an optimization, without the stored session and stats.
v1::OptimizeComeshResult OptimizeResult(const solver::Multimesh& mesh,
                                        const solver::ComeshReport& report,
                                        const solver::ComeshCheckpoint* resumed_from) {
  v1::OptimizeComeshResult result;
  *result.mutable_multimesh() = ToProto(mesh);
  result.set_inner_iterations(report.inner);
  result.set_outer_iterations(report.outer);
  result.set_seconds(report.seconds);
  if (resumed_from != nullptr) {
    result.set_resumed_outer(resumed_from->outer);
    result.set_resumed_inner(resumed_from->inner);
  }
  return result;
}

int MaxDrawings(const ServiceOptions& options) {
  return std::clamp(options.limits.max_drawings, 2, kMaxDrawingsPerSession);
}

// --max-sessions-per-token (only with --tokens: without them every caller is the same owner).
absl::Status CheckSessionQuota(const SessionStore& store, const ServiceOptions& options,
                               const Caller& caller) {
  if (!options.tokens) return absl::OkStatus();
  const size_t owned = store.CountOwned(caller.owner);
  if (owned >= options.limits.max_sessions_per_token) {
    return solver::WithReason(absl::ResourceExhaustedError(absl::StrCat(
                                  "this token already has ", owned, " sessions, the limit is ",
                                  options.limits.max_sessions_per_token,
                                  " (--max-sessions-per-token); delete some first")),
                              solver::kReasonSessionsPerToken);
  }
  return absl::OkStatus();
}

absl::Status CheckMeshVertices(const solver::Multimesh& mesh, const ServiceOptions& options,
                               absl::string_view what) {
  if (mesh.num_vertices() > options.limits.max_mesh_vertices) {
    return absl::ResourceExhaustedError(absl::StrCat(
        what, " has ", mesh.num_vertices(), " vertices, the limit is ",
        options.limits.max_mesh_vertices,
        " (--max-mesh-vertices); use fewer boundary_vertices or a larger max_edge_relative"));
  }
  return absl::OkStatus();
}

// A heavy-job slot for this call; a busy answer carries trailing metadata retry-after-ms.
absl::StatusOr<HeavyJobs::Slot> AcquireHeavy(HeavyJobs& heavy, grpc::ServerContext* context,
                                             const Caller& caller) {
  absl::StatusOr<HeavyJobs::Slot> slot =
      heavy.Acquire(caller.owner, [context] { return context->IsCancelled(); });
  if (slot.status().code() == absl::StatusCode::kResourceExhausted) {
    context->AddTrailingMetadata("retry-after-ms",
                                 absl::StrCat(solver::RetryAfterMs(slot.status())));
  }
  if (slot.status().code() == absl::StatusCode::kCancelled) {
    return StoppedStatus(*context, "the call");
  }
  return slot;
}

}  // namespace

InbetweenService::InbetweenService(std::shared_ptr<SessionStore> store, ServiceOptions options)
    : store_(std::move(store)), options_(std::move(options)), heavy_(options_.heavy) {}

// ---------------------------------------------------------------------------------------------
// Sessions

grpc::Status InbetweenService::CreateSession(grpc::ServerContext* context,
                                             const v1::CreateSessionRequest* request,
                                             v1::CreateSessionResponse* response) {
  std::string session_id;
  Caller caller;
  return RunRpc(options_, context, "CreateSession", session_id, &caller, [&]() -> absl::Status {
    if (auto s = CheckName(request->display_name(), "display_name"); !s.ok()) return s;
    if (auto s = ValidateParameters(request->parameters(), "parameters"); !s.ok()) return s;
    SessionState state;
    state.session.set_display_name(request->display_name());
    *state.session.mutable_parameters() = request->parameters();
    state.session.set_stage(v1::STAGE_UNSPECIFIED);
    state.owner = caller.owner;
    if (auto s = CheckSessionQuota(*store_, options_, caller); !s.ok()) return s;
    absl::StatusOr<SessionState> stored = store_->Create(std::move(state));
    if (!stored.ok()) return stored.status();
    session_id = stored->session.id();
    *response->mutable_session() = stored->session;
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::GetSession(grpc::ServerContext* context,
                                          const v1::GetSessionRequest* request,
                                          v1::GetSessionResponse* response) {
  Caller caller;
  return RunRpc(options_, context, "GetSession", request->session_id(), &caller,
                [&]() -> absl::Status {
                  absl::StatusOr<SessionState> state = Load(*store_, request->session_id(), caller);
                  if (!state.ok()) return state.status();
                  if (request->full()) {
                    *response->mutable_session() = state->session;
                    if (state->multimesh)
                      *response->mutable_multimesh() = ToProto(*state->multimesh);
                  } else {
                    *response->mutable_session() = Compact(state->session);
                  }
                  return absl::OkStatus();
                });
}

grpc::Status InbetweenService::ListSessions(grpc::ServerContext* context,
                                            const v1::ListSessionsRequest* request,
                                            v1::ListSessionsResponse* response) {
  Caller caller;
  return RunRpc(options_, context, "ListSessions", "", &caller, [&]() -> absl::Status {
    // Page sizes above the maximum are clamped (AIP-158), not rejected.
    const uint32_t page_size =
        request->page_size() == 0 ? kDefaultPageSize : std::min(request->page_size(), kMaxPageSize);
    absl::StatusOr<SessionPage> page = store_->List(page_size, request->page_token(), caller.owner);
    if (!page.ok()) return page.status();
    for (const SessionState& state : page->sessions) {
      *response->add_sessions() = SessionSummary(state.session);
    }
    response->set_next_page_token(page->next_page_token);
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::DeleteSession(grpc::ServerContext* context,
                                             const v1::DeleteSessionRequest* request,
                                             v1::DeleteSessionResponse*) {
  Caller caller;
  return RunRpc(options_, context, "DeleteSession", request->session_id(), &caller,
                [&]() -> absl::Status {
                  // Load first: another owner's session is NOT_FOUND.
                  if (auto state = Load(*store_, request->session_id(), caller); !state.ok()) {
                    return state.status();
                  }
                  return store_->Delete(request->session_id(), request->expected_version());
                });
}

grpc::Status InbetweenService::ExportSession(grpc::ServerContext* context,
                                             const v1::ExportSessionRequest* request,
                                             v1::ExportSessionResponse* response) {
  Caller caller;
  return RunRpc(options_, context, "ExportSession", request->session_id(), &caller,
                [&]() -> absl::Status {
                  absl::StatusOr<SessionState> state = Load(*store_, request->session_id(), caller);
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

grpc::Status InbetweenService::ImportSession(grpc::ServerContext* context,
                                             const v1::ImportSessionRequest* request,
                                             v1::ImportSessionResponse* response) {
  std::string session_id = request->session_id();
  Caller caller;
  return RunRpc(options_, context, "ImportSession", session_id, &caller, [&]() -> absl::Status {
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
    state.owner = caller.owner;
    if (auto s = CheckSessionQuota(*store_, options_, caller); !s.ok()) return s;
    v1::Session& session = state.session;
    if (auto s = CheckName(session.display_name(), "data: session.display_name"); !s.ok()) {
      return s;
    }
    if (auto s = ValidateParameters(session.parameters(), "data: session.parameters"); !s.ok()) {
      return s;
    }
    if (session.drawings_size() > MaxDrawings(options_)) {
      return absl::ResourceExhaustedError(
          absl::StrCat("data: the session has ", session.drawings_size(),
                       " drawings, the limit is ", MaxDrawings(options_), " (--max-drawings)"));
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
          drawing.elements().empty()
              ? ImportDrawing(drawing, {}, field, i + 1, {}, "topology",
                              options_.limits.max_drawing_points)
              : ImportDrawingElements(drawing, field, i + 1, options_.limits.max_drawing_points);
      if (!imported.ok()) return imported.status();
      StoreImport(*imported, &drawing);
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
      if (absl::Status s = CheckMeshVertices(*mesh, options_, "data: multimesh"); !s.ok()) {
        return s;
      }
      if (mesh->num_shapes() != session.drawings_size()) {
        return absl::InvalidArgumentError(absl::StrCat("data: multimesh has ", mesh->num_shapes(),
                                                       " shapes for ", session.drawings_size(),
                                                       " drawings"));
      }
      // The art is embedded again from the drawings, which are what it shows (an archive
      // written before the multimesh carried art has none).
      absl::StatusOr<std::vector<solver::EmbeddedArt>> art =
          solver::EmbedDrawingsArt(*mesh, state.parsed);
      if (!art.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("data: art: ", art.status().message()));
      }
      mesh->art = *std::move(art);
      if (auto s = solver::ValidateMultimesh(*mesh); !s.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("data: multimesh: ", s.message()));
      }
      v1::MultimeshStats stats = StatsOf(*mesh);
      stats.set_map_energy(session.multimesh_stats().map_energy());
      stats.set_mesh_energy(session.multimesh_stats().mesh_energy());
      KeepBuildFacts(session.multimesh_stats(), &stats);
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

grpc::Status InbetweenService::PutDrawing(grpc::ServerContext* context,
                                          const v1::PutDrawingRequest* request,
                                          v1::PutDrawingResponse* response) {
  Caller caller;
  return RunRpc(
      options_, context, "PutDrawing", request->session_id(), &caller, [&]() -> absl::Status {
        absl::StatusOr<SessionState> state =
            LoadForUpdate(*store_, request->session_id(), request->expected_version(), caller);
        if (!state.ok()) return state.status();
        v1::Session& session = state->session;
        const uint32_t drawing_id = request->drawing().id();
        const bool add = drawing_id == 0;
        const int index = add ? session.drawings_size() : FindDrawing(session, drawing_id);
        if (add && session.drawings_size() >= MaxDrawings(options_)) {
          return absl::ResourceExhaustedError(
              absl::StrCat("session ", session.id(), " already has the maximum of ",
                           MaxDrawings(options_), " drawings (--max-drawings)"));
        }
        if (index < 0) {
          return absl::NotFoundError(
              absl::StrCat("drawing ", drawing_id, " not found in session ", session.id()));
        }
        // SVG parsing and graph flow run here, outside the store's lock.
        const DrawingImportOptions import_options{
            .flatten_tolerance = request->flatten_tolerance(),
            .gap_tolerance = request->gap_tolerance(),
            .min_area_fraction = request->min_area_fraction()};
        absl::StatusOr<ImportedDrawing> imported =
            ImportDrawing(request->drawing(), import_options, "drawing", index + 1,
                          request->topology(), "topology", options_.limits.max_drawing_points);
        if (!imported.ok()) return imported.status();

        v1::Drawing drawing = request->drawing();
        StoreImport(*imported, &drawing);
        if (add) {
          drawing.set_id(state->next_drawing_id++);
          *session.add_drawings() = drawing;
          state->parsed.push_back(std::move(imported->parsed));
          // Each mark has one point per drawing; with a new drawing the old marks no longer fit.
          session.clear_correspondences();
        } else {
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
        *response->mutable_import_report() = imported->import_report;
        return absl::OkStatus();
      });
}

grpc::Status InbetweenService::RemoveDrawing(grpc::ServerContext* context,
                                             const v1::RemoveDrawingRequest* request,
                                             v1::RemoveDrawingResponse* response) {
  Caller caller;
  return RunRpc(
      options_, context, "RemoveDrawing", request->session_id(), &caller, [&]() -> absl::Status {
        absl::StatusOr<SessionState> state =
            LoadForUpdate(*store_, request->session_id(), request->expected_version(), caller);
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
    grpc::ServerContext* context,
    grpc::ServerReaderWriter<v1::TopologyState, v1::TopologyEdit>* stream) {
  std::string session_id;
  Caller caller;
  return RunRpc(options_, context, "EditTopology", session_id, &caller, [&]() -> absl::Status {
    v1::TopologyEdit edit;
    for (int n = 0; stream->Read(&edit); ++n) {
      if (n == 0) {
        session_id = edit.session_id();
      } else if (edit.session_id() != session_id) {
        return absl::InvalidArgumentError(
            absl::StrCat("edit ", n, ": session_id '", edit.session_id(),
                         "' differs from the stream's session '", session_id, "'"));
      }
      absl::StatusOr<SessionState> state =
          LoadForUpdate(*store_, edit.session_id(), edit.expected_version(), caller);
      if (!state.ok()) return state.status();
      absl::StatusOr<v1::TopologyState> reply =
          ApplyTopologyEdit(edit, n, options_.limits.max_drawing_points, *state);
      if (!reply.ok()) return reply.status();
      absl::StatusOr<SessionState> stored = store_->Put(*std::move(state), edit.expected_version());
      if (!stored.ok()) return stored.status();
      reply->set_version(stored->session.version());
      if (!stream->Write(*reply)) return StoppedStatus(*context, "EditTopology");
    }
    if (context->IsCancelled()) return StoppedStatus(*context, "EditTopology");
    return absl::OkStatus();
  });
}

grpc::Status InbetweenService::SetCorrespondences(grpc::ServerContext* context,
                                                  const v1::SetCorrespondencesRequest* request,
                                                  v1::SetCorrespondencesResponse* response) {
  Caller caller;
  return RunRpc(
      options_, context, "SetCorrespondences", request->session_id(), &caller,
      [&]() -> absl::Status {
        absl::StatusOr<SessionState> state =
            LoadForUpdate(*store_, request->session_id(), request->expected_version(), caller);
        if (!state.ok()) return state.status();
        if (auto s = CheckCorrespondences(request->correspondences(),
                                          state->session.drawings_size(), "correspondences");
            !s.ok()) {
          return s;
        }
        // BuildMultimesh pins the marks (MultimeshOptions::marks): a mesh built without them is
        // stale.
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

namespace {

// The meshing parameters BuildMultimesh uses (the request's, else the session's), once the
// session has two drawings and they are valid and within --max-mesh-vertices.
absl::StatusOr<const v1::MeshingParameters*> MeshingToBuild(
    const v1::BuildMultimeshRequest& request, const v1::Session& session,
    const ServiceLimits& limits) {
  if (session.drawings_size() < 2) {
    return absl::FailedPreconditionError(
        absl::StrCat("BuildMultimesh needs at least 2 drawings, session ", request.session_id(),
                     " has ", session.drawings_size()));
  }
  const bool own_meshing = request.has_meshing();
  const v1::MeshingParameters& meshing =
      own_meshing ? request.meshing() : session.parameters().meshing();
  if (auto s = ValidateMeshing(meshing, own_meshing ? "meshing" : "session parameters.meshing");
      !s.ok()) {
    return s;
  }
  if (meshing.boundary_vertices() > static_cast<uint32_t>(limits.max_mesh_vertices)) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "meshing.boundary_vertices = ", meshing.boundary_vertices(), " exceeds the limit of ",
        limits.max_mesh_vertices, " mesh vertices (--max-mesh-vertices)"));
  }
  return &meshing;
}

// The builder's answer as the service's: a vertex-limit failure names --max-mesh-vertices, and a
// mesh is within it, has one shape per drawing and is valid (the solver promises a valid mesh; a
// stored multimesh is never silently flipped).
absl::Status CheckBuiltMesh(const absl::StatusOr<solver::Multimesh>& mesh, int drawings,
                            const ServiceOptions& options) {
  // The mesher's refinement stops at --max-mesh-vertices; say which limit it hit.
  if (solver::ErrorReason(mesh.status()) == solver::kReasonMeshVertexLimit) {
    return absl::ResourceExhaustedError(absl::StrCat(
        mesh.status().message(), "; the limit is ", options.limits.max_mesh_vertices,
        " mesh vertices (--max-mesh-vertices): use fewer boundary_vertices or a larger "
        "max_edge_relative"));
  }
  if (!mesh.ok()) return mesh.status();
  if (absl::Status s = CheckMeshVertices(*mesh, options, "the multimesh"); !s.ok()) return s;
  if (mesh->num_shapes() != drawings) {
    return absl::InternalError(absl::StrCat("the multimesh builder returned ", mesh->num_shapes(),
                                            " shapes for ", drawings, " drawings"));
  }
  if (absl::Status s = solver::ValidateMultimesh(*mesh); !s.ok()) {
    return absl::InternalError(
        absl::StrCat("the multimesh builder returned an invalid mesh: ", s.message()));
  }
  return absl::OkStatus();
}

// After every topology pass OptimizeComesh stores the checkpoint with the session, at the same
// version (nothing a client reads changes). A failed write (another writer, or the store is down)
// cancels the run: its final write would fail the same way.
class CheckpointSaver {
 public:
  CheckpointSaver(SessionStore& store, const SessionState& state, std::string parameters,
                  solver::CancelToken& token, grpc::ServerContext& context)
      : store_(store),
        state_(state),
        parameters_(std::move(parameters)),
        token_(token),
        context_(context) {}

  void Save(const solver::ComeshCheckpoint& c) {
    if (token_.IsCancelled() || context_.IsCancelled()) return;
    const uint64_t version = state_.session.version();
    auto stored = std::make_shared<StoredComeshCheckpoint>();
    stored->input_version = version;
    stored->stored_version = version;
    stored->parameters = parameters_;
    stored->checkpoint = c;
    SessionState next = state_;
    next.comesh_checkpoint = std::move(stored);
    absl::StatusOr<SessionState> put = store_.PutSameVersion(std::move(next), version);
    if (!put.ok()) {
      status_ = put.status();
      token_.Cancel();
    }
  }
  // OK unless a write failed.
  const absl::Status& status() const { return status_; }

 private:
  SessionStore& store_;
  const SessionState& state_;  // the session as loaded: every checkpoint replaces the last
  const std::string parameters_;
  solver::CancelToken& token_;
  grpc::ServerContext& context_;
  absl::Status status_;
};

// A built multimesh's stats: its counts and the build's facts (seconds, corner-matched loops,
// overlays, vertices per loop, achieved outline tolerance).
v1::MultimeshStats BuildStats(const solver::Multimesh& mesh, const solver::MultimeshReport& report,
                              double seconds) {
  v1::MultimeshStats stats = StatsOf(mesh);
  stats.set_build_seconds(report.seconds > 0 ? report.seconds : seconds);
  stats.set_corner_matched_loops(static_cast<uint32_t>(report.corner_matched_loops));
  stats.set_overlays(static_cast<uint32_t>(report.overlays));
  for (const int n : report.loop_vertices) stats.add_loop_vertices(static_cast<uint32_t>(n));
  stats.set_achieved_tolerance(report.achieved_tolerance);
  return stats;
}

}  // namespace

grpc::Status InbetweenService::BuildMultimesh(
    grpc::ServerContext* context, const v1::BuildMultimeshRequest* request,
    grpc::ServerWriter<v1::BuildMultimeshResponse>* writer) {
  Caller caller;
  return RunRpc(
      options_, context, "BuildMultimesh", request->session_id(), &caller, [&]() -> absl::Status {
        absl::StatusOr<SessionState> state =
            LoadForUpdate(*store_, request->session_id(), request->expected_version(), caller);
        if (!state.ok()) return state.status();
        absl::StatusOr<const v1::MeshingParameters*> chosen =
            MeshingToBuild(*request, state->session, options_.limits);
        if (!chosen.ok()) return chosen.status();
        const v1::MeshingParameters& meshing = **chosen;
        absl::StatusOr<HeavyJobs::Slot> slot = AcquireHeavy(heavy_, context, caller);
        if (!slot.ok()) return slot.status();

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
        solver::MultimeshOptions options = ToMultimeshOptions(meshing);
        options.max_mesh_vertices = options_.limits.max_mesh_vertices;  // bounds the refinement
        for (const v1::Correspondence& mark : state->session.correspondences()) {
          options.marks.push_back(FromProto(mark.points()));
        }
        absl::StatusOr<solver::Multimesh> mesh =
            solver::BuildMultimesh(state->parsed, options, &token, progress, &report);
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        if (token.IsCancelled() || context->IsCancelled()) {
          return StoppedStatus(*context, "BuildMultimesh");
        }
        if (options_.metrics) options_.metrics->ObserveStage("build", seconds);
        if (absl::Status s = CheckBuiltMesh(mesh, state->session.drawings_size(), options_);
            !s.ok()) {
          return s;
        }
        const v1::MultimeshStats stats = BuildStats(*mesh, report, seconds);

        v1::BuildMultimeshResponse message;
        v1::BuildMultimeshResult* result = message.mutable_result();
        *result->mutable_multimesh() = ToProto(*mesh);
        state->multimesh = std::make_shared<const solver::Multimesh>(*std::move(mesh));
        state->comesh_checkpoint.reset();  // of the previous multimesh
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

grpc::Status InbetweenService::OptimizeComesh(
    grpc::ServerContext* context, const v1::OptimizeComeshRequest* request,
    grpc::ServerWriter<v1::OptimizeComeshResponse>* writer) {
  Caller caller;
  return RunRpc(
      options_, context, "OptimizeComesh", request->session_id(), &caller, [&]() -> absl::Status {
        absl::StatusOr<SessionState> state =
            LoadForUpdate(*store_, request->session_id(), request->expected_version(), caller,
                          /*latest=*/request->resume());
        if (!state.ok()) return state.status();
        const std::shared_ptr<const StoredComeshCheckpoint> checkpoint = state->comesh_checkpoint;
        if (state->session.stage() < v1::STAGE_MULTIMESH || !state->multimesh) {
          return absl::FailedPreconditionError(
              absl::StrCat("session ", request->session_id(),
                           " has no multimesh: build the multimesh first (BuildMultimesh)"));
        }
        const bool own_comesh = request->has_comesh();
        const v1::ComeshParameters& comesh =
            own_comesh ? request->comesh() : state->session.parameters().comesh();
        if (auto s = ValidateComesh(comesh, own_comesh ? "comesh" : "session parameters.comesh");
            !s.ok()) {
          return s;
        }
        const std::string parameters_key = comesh.SerializeAsString();
        const solver::ComeshCheckpoint* resume_from =
            CheckpointToResume(*request, *state, parameters_key);
        solver::ComeshOptions options = ComeshOptionsFor(*state, comesh);
        options.threads = options_.solver_threads;
        absl::StatusOr<HeavyJobs::Slot> slot = AcquireHeavy(heavy_, context, caller);
        if (!slot.ok()) return slot.status();

        solver::CancelToken token;
        CancelWatcher watcher(context, &token);
        std::mutex write_mutex;
        auto write = [&](const v1::OptimizeComeshResponse& message) {
          std::lock_guard lock(write_mutex);
          if (!writer->Write(message)) token.Cancel();
        };
        if (resume_from != nullptr) write(ResumedNotice(*resume_from, checkpoint->stored_version));
        // One ComeshIteration per accepted iterate: on_iterate opens it (iteration number, vertex
        // count), the progress call that follows in the same iteration adds the energies.
        ComeshIterationStream iterations(
            resume_from != nullptr ? static_cast<uint32_t>(resume_from->outer) : 0);
        options.on_iterate = [&](int iteration, const std::vector<solver::Points>& shapes) {
          if (std::optional<v1::OptimizeComeshResponse> done =
                  iterations.Begin(iteration, shapes)) {
            write(*done);
          }
        };
        solver::ProgressFn progress = [&](const std::string& stage, double fraction,
                                          const std::string& detail) {
          if (context->IsCancelled()) {
            token.Cancel();
            return;
          }
          write(iterations.OnProgress(stage, fraction, detail));
        };
        const uint64_t version = state->session.version();
        CheckpointSaver saver(*store_, *state, parameters_key, token, *context);
        options.on_checkpoint = [&saver](const solver::ComeshCheckpoint& c) { saver.Save(c); };
        solver::ComeshReport report;
        absl::StatusOr<solver::Multimesh> mesh = solver::OptimizeComesh(
            *state->multimesh, options, &token, progress, &report, resume_from);
        if (std::optional<v1::OptimizeComeshResponse> last = iterations.Flush()) write(*last);
        if (options_.metrics) options_.metrics->ObserveStage("optimize", report.seconds);
        if (!saver.status().ok()) return saver.status();
        if (token.IsCancelled() || context->IsCancelled()) {
          return StoppedStatus(*context, "OptimizeComesh");
        }
        if (!mesh.ok()) return mesh.status();
        if (absl::Status s = EmbedArtAndValidate(state->parsed, &*mesh); !s.ok()) return s;
        v1::MultimeshStats stats = StatsOf(*mesh);
        stats.set_map_energy(report.map_energy);
        stats.set_mesh_energy(report.mesh_energy);
        KeepBuildFacts(state->session.multimesh_stats(), &stats);

        v1::OptimizeComeshResponse message;
        v1::OptimizeComeshResult* result = message.mutable_result();
        *result = OptimizeResult(*mesh, report, resume_from);
        state->multimesh = std::make_shared<const solver::Multimesh>(*std::move(mesh));
        state->comesh_checkpoint.reset();  // done: nothing to resume
        state->session.set_stage(v1::STAGE_OPTIMIZED);
        *state->session.mutable_multimesh_stats() = stats;
        absl::StatusOr<SessionState> stored = store_->Put(*std::move(state), version);
        if (!stored.ok()) return stored.status();
        *result->mutable_session() = Compact(stored->session);
        *result->mutable_stats() = stats;
        std::lock_guard lock(write_mutex);
        if (!writer->Write(message)) return StoppedStatus(*context, "OptimizeComesh");
        return absl::OkStatus();
      });
}

grpc::Status InbetweenService::Inbetween(grpc::ServerContext* context,
                                         const v1::InbetweenRequest* request,
                                         grpc::ServerWriter<v1::InbetweenResponse>* writer) {
  Caller caller;
  return RunRpc(
      options_, context, "Inbetween", request->session_id(), &caller, [&]() -> absl::Status {
        absl::StatusOr<SessionState> state = Load(*store_, request->session_id(), caller);
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
        plan->options.threads = options_.solver_threads;
        const absl::StatusOr<solver::Schedule> schedule = ScheduleFrames(
            parameters, session, plan->frames, request->start_frame(), options_.limits.max_frames);
        if (!schedule.ok()) return schedule.status();

        absl::StatusOr<HeavyJobs::Slot> slot = AcquireHeavy(heavy_, context, caller);
        if (!slot.ok()) return slot.status();
        const Clock::time_point stage_start = Clock::now();
        struct StageTimer {
          Metrics* metrics;
          Clock::time_point start;
          ~StageTimer() {
            if (metrics) {
              metrics->ObserveStage("inbetween",
                                    std::chrono::duration<double>(Clock::now() - start).count());
            }
          }
        } stage_timer{options_.metrics.get(), stage_start};

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
        const std::vector<v1::InbetweenResponse> art_messages = AddKeyArt(mesh, header);
        if (!writer->Write(message)) return StoppedStatus(*context, "Inbetween");
        for (const v1::InbetweenResponse& art : art_messages) {
          if (!writer->Write(art)) return StoppedStatus(*context, "Inbetween");
        }

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
          if (options_.metrics) options_.metrics->CountFrameSolved();
          if (token.IsCancelled()) return StoppedStatus(*context, "Inbetween");
          if (!frame.ok()) {
            return absl::Status(frame.status().code(),
                                absl::StrCat("frame ", i, ": ", frame.status().message()));
          }
          if (static_cast<int>(frame->vertices.size()) != mesh.num_vertices()) {
            return absl::InternalError(absl::StrCat("frame ", i, " has ", frame->vertices.size(),
                                                    " vertices, the mesh has ",
                                                    mesh.num_vertices()));
          }
          if (i >= static_cast<int>(request->start_frame())) {
            message.Clear();
            *message.mutable_frame() = FrameMessage(i, timing, *frame, report, seconds);
            if (!writer->Write(message)) return StoppedStatus(*context, "Inbetween");
          }
          previous = *std::move(frame);
        }
        return absl::OkStatus();
      });
}

}  // namespace inbetween::server
