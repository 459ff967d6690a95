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

class InbetweenClient {
 public:
  explicit InbetweenClient(std::shared_ptr<grpc::Channel> channel);

  absl::StatusOr<v1::Session> CreateSession(const std::string& display_name);
  // Adds an SVG drawing (the file's text) named `name`; returns the updated session.
  absl::StatusOr<v1::PutDrawingResponse> PutSvgDrawing(const v1::Session& session,
                                                       const std::string& name,
                                                       const std::string& svg_text);
  absl::StatusOr<v1::BuildMultimeshResult> BuildMultimesh(const v1::Session& session,
                                                          const ProgressCallback& progress);
  // Streams all frames; `on_frame` (optional) sees each frame as it arrives.
  absl::StatusOr<FramesResult> Inbetween(
      const std::string& session_id, const v1::InbetweenParameters& parameters,
      const std::function<void(const v1::InbetweenFrame&, uint32_t total)>& on_frame);

  // Cancels the RPC in flight (if any) from another thread, e.g. a SIGINT handler thread.
  void CancelInFlight();

 private:
  // Registers `context` as the in-flight call for CancelInFlight().
  void SetInFlight(grpc::ClientContext* context);

  std::unique_ptr<v1::Inbetween::Stub> stub_;
  std::mutex mu_;
  grpc::ClientContext* in_flight_ = nullptr;
  bool cancelled_ = false;
};

}  // namespace inbetween::client
