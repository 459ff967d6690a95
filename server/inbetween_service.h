// The inbetween.v1.Inbetween gRPC service (sync API). Handlers are thin: validate the request,
// copy the session out of the store, run the solver stage without holding any lock, put the
// result back with a version check, map the status once (ToGrpcStatus), reply.
#pragma once

#include <memory>

#include "inbetween/v1/inbetween.grpc.pb.h"
#include "server/auth.h"
#include "server/drawing_import.h"
#include "server/heavy_jobs.h"
#include "server/metrics.h"
#include "server/parameters.h"
#include "server/session_store.h"

namespace inbetween::server {

inline constexpr int kMaxDrawingsPerSession = 16;
inline constexpr uint32_t kDefaultPageSize = 100;
inline constexpr uint32_t kMaxPageSize = 1000;

// Limits enforced by the handlers (flags of inbetween-server); each error names its flag.
struct ServiceLimits {
  int max_drawings = kMaxDrawingsPerSession;      // --max-drawings (shapes per session, <= 16)
  int max_drawing_points = kMaxPointsPerDrawing;  // --max-drawing-points
  int max_mesh_vertices = 2'000'000;              // --max-mesh-vertices
  int max_frames = kMaxFrames;                    // --max-frames (per Inbetween request)
  size_t max_sessions_per_token = 1000;           // --max-sessions-per-token
};

struct ServiceOptions {
  ServiceLimits limits;
  HeavyJobOptions heavy;
  std::shared_ptr<const TokenTable> tokens;  // null = no authentication
  std::shared_ptr<Metrics> metrics;          // null = not collected
  // Successful RPCs are logged at info (inbetween-server) or debug (embedded, tests).
  bool log_ok_rpcs_at_info = false;
  // Threads one heavy job's solver uses (--solver-threads). Results are bit-identical for every
  // value; more threads only pay on large meshes (see solver/core/parallel_chunks.h).
  int solver_threads = 1;
};

class InbetweenService final : public inbetween::v1::Inbetween::Service {
 public:
  explicit InbetweenService(std::shared_ptr<SessionStore> store, ServiceOptions options = {});

  // Heavy jobs running and waiting (for metrics).
  const HeavyJobs& heavy_jobs() const { return heavy_; }

  grpc::Status CreateSession(grpc::ServerContext* context,
                             const inbetween::v1::CreateSessionRequest* request,
                             inbetween::v1::CreateSessionResponse* response) override;
  grpc::Status GetSession(grpc::ServerContext* context,
                          const inbetween::v1::GetSessionRequest* request,
                          inbetween::v1::GetSessionResponse* response) override;
  grpc::Status ListSessions(grpc::ServerContext* context,
                            const inbetween::v1::ListSessionsRequest* request,
                            inbetween::v1::ListSessionsResponse* response) override;
  grpc::Status DeleteSession(grpc::ServerContext* context,
                             const inbetween::v1::DeleteSessionRequest* request,
                             inbetween::v1::DeleteSessionResponse* response) override;
  grpc::Status ExportSession(grpc::ServerContext* context,
                             const inbetween::v1::ExportSessionRequest* request,
                             inbetween::v1::ExportSessionResponse* response) override;
  grpc::Status ImportSession(grpc::ServerContext* context,
                             const inbetween::v1::ImportSessionRequest* request,
                             inbetween::v1::ImportSessionResponse* response) override;

  grpc::Status PutDrawing(grpc::ServerContext* context,
                          const inbetween::v1::PutDrawingRequest* request,
                          inbetween::v1::PutDrawingResponse* response) override;
  grpc::Status RemoveDrawing(grpc::ServerContext* context,
                             const inbetween::v1::RemoveDrawingRequest* request,
                             inbetween::v1::RemoveDrawingResponse* response) override;
  grpc::Status EditTopology(grpc::ServerContext* context,
                            grpc::ServerReaderWriter<inbetween::v1::TopologyState,
                                                     inbetween::v1::TopologyEdit>* stream) override;
  grpc::Status SetCorrespondences(grpc::ServerContext* context,
                                  const inbetween::v1::SetCorrespondencesRequest* request,
                                  inbetween::v1::SetCorrespondencesResponse* response) override;

  grpc::Status BuildMultimesh(
      grpc::ServerContext* context, const inbetween::v1::BuildMultimeshRequest* request,
      grpc::ServerWriter<inbetween::v1::BuildMultimeshResponse>* writer) override;
  grpc::Status OptimizeComesh(
      grpc::ServerContext* context, const inbetween::v1::OptimizeComeshRequest* request,
      grpc::ServerWriter<inbetween::v1::OptimizeComeshResponse>* writer) override;
  grpc::Status Inbetween(grpc::ServerContext* context,
                         const inbetween::v1::InbetweenRequest* request,
                         grpc::ServerWriter<inbetween::v1::InbetweenResponse>* writer) override;

 private:
  std::shared_ptr<SessionStore> store_;
  ServiceOptions options_;
  HeavyJobs heavy_;
};

}  // namespace inbetween::server
