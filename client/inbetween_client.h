// A thin C++ client for the Inbetween gRPC API, shared by the CLI and tests. Each call is one RPC
// (or one whole stream) and returns absl::Status so callers map errors once.
#pragma once

#include <grpcpp/grpcpp.h>

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inbetween/v1/inbetween.grpc.pb.h"

namespace inbetween::client {

// grpc::Status -> absl::Status (same code, same message).
absl::Status FromGrpcStatus(const grpc::Status& status);

// The frames of one Inbetween stream, as received.
struct FramesResult {
  v1::InbetweenHeader header;
  std::vector<v1::InbetweenFrame> frames;
};

using ProgressCallback = std::function<void(const v1::Progress&)>;

struct ClientOptions {
  std::string token;  // bearer token sent as "authorization: Bearer <token>"; empty = none
};

class InbetweenClient {
 public:
  explicit InbetweenClient(std::shared_ptr<grpc::Channel> channel, ClientOptions options = {});

  absl::StatusOr<v1::Session> CreateSession(const std::string& display_name,
                                            const v1::Parameters& parameters = {});
  absl::StatusOr<v1::GetSessionResponse> GetSession(const std::string& session_id, bool full);
  // Every session of the caller (all pages).
  absl::StatusOr<std::vector<v1::Session>> ListSessions();
  absl::StatusOr<v1::PutDrawingResponse> PutDrawing(const v1::PutDrawingRequest& request);
  absl::StatusOr<v1::Session> SetCorrespondences(const v1::SetCorrespondencesRequest& request);
  absl::StatusOr<v1::BuildMultimeshResult> BuildMultimesh(const v1::Session& session,
                                                          const ProgressCallback& progress);
  absl::StatusOr<v1::OptimizeComeshResult> OptimizeComesh(
      const v1::Session& session, const std::function<void(const v1::ComeshIteration&)>& on_iter,
      const ProgressCallback& progress);
  // Streams all frames; `on_frame` (optional) sees each frame as it arrives.
  absl::StatusOr<FramesResult> Inbetween(
      const std::string& session_id, const v1::InbetweenParameters& parameters,
      const std::function<void(const v1::InbetweenFrame&, uint32_t total)>& on_frame);

  // Cancels the RPC in flight (if any) and every later one, from another thread (Ctrl-C).
  void CancelInFlight();

 private:
  // A context carrying the token and the session id (for proxies' session affinity), registered
  // as the in-flight call for CancelInFlight() until it is destroyed.
  class Call;

  std::unique_ptr<v1::Inbetween::Stub> stub_;
  ClientOptions options_;
  std::mutex mu_;
  grpc::ClientContext* in_flight_ = nullptr;
  bool cancelled_ = false;
};

}  // namespace inbetween::client
