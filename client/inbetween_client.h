// A thin C++ client for the Inbetween gRPC API, shared by the CLI and tests. Each call is one RPC
// (or one whole stream) and returns absl::Status so callers map errors once.
//
// Failover (docs/scale-out.md): behind a proxy in front of replicas, a replica may die in the
// middle of a call. `Inbetween` then resumes on another replica from the next frame not yet
// received (`start_frame`; the solver is deterministic, so the frames equal an uninterrupted
// run), `OptimizeComesh` is sent again with `resume` (the server continues from the checkpoint
// it stored after the last topology pass; the result equals an uninterrupted run's), and the
// read-only unary calls (GetSession, ListSessions) are sent again; all with exponential backoff
// and a bounded number of attempts (RetryOptions).
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inbetween/v1/inbetween.grpc.pb.h"

namespace inbetween::client {

// grpc::Status -> absl::Status (same code, same message), except gRPC's own message-size
// refusals: a request or reply over the server's --max-message-bytes is refused by gRPC before
// any handler runs, as RESOURCE_EXHAUSTED "Received message larger than max (A vs. B)" (the
// request) or "Sent message larger than max (A vs. B)" (the reply), naming no flag. Those become
// "the request is A bytes, over the server's limit of B bytes (inbetween-server
// --max-message-bytes B) ..." with gRPC's text kept at the end (docs/hardening.md). On a channel
// from CreateChannelForServer (no receive limit of the client's own) every such refusal is the
// server's.
absl::Status FromGrpcStatus(const grpc::Status& status);

// A channel to a remote inbetween-server without gRPC's default 4 MiB receive limit: the server's
// --max-message-bytes bounds its replies (its default, 64 MiB, is what the embedded service's
// in-process channel allows), and a size refusal is then always the server's limit.
std::shared_ptr<grpc::Channel> CreateChannelForServer(
    const std::string& target, const std::shared_ptr<grpc::ChannelCredentials>& credentials);

// The frames of one Inbetween stream, as received.
struct FramesResult {
  // The header, with the layers of every InbetweenResponse.art message appended to its KeyArt
  // (art_messages says how many there were).
  v1::InbetweenHeader header;
  std::vector<v1::InbetweenFrame> frames;
};

using ProgressCallback = std::function<void(const v1::Progress&)>;

// Retries of calls that are safe to repeat, after a transient failure (IsTransient).
struct RetryOptions {
  int max_attempts = 5;  // per call, the first one included; 1 = never retry
  std::chrono::milliseconds initial_backoff{100};  // wait before the 2nd attempt
  double multiplier = 2.0;                         // each later wait is this much longer
  std::chrono::milliseconds max_backoff{5000};     // cap of one wait
};

// One retry about to happen, for logging (ClientOptions::on_retry).
struct RetryEvent {
  std::string method;                 // "Inbetween", "GetSession", "ListSessions"
  int failed_attempt = 0;             // 1 = the first attempt failed
  absl::Status status;                // why it failed
  std::chrono::milliseconds backoff;  // wait before the next attempt
  uint32_t resume_frame = 0;          // Inbetween: start_frame of the next attempt
  uint32_t last_iteration = 0;        // OptimizeComesh: the last iteration received
};

struct ClientOptions {
  std::string token;  // bearer token sent as "authorization: Bearer <token>"; empty = none
  RetryOptions retry;
  std::function<void(const RetryEvent&)> on_retry;  // optional; called before each wait
};

// Whether a failed call may be repeated on another replica: UNAVAILABLE (replica unreachable,
// draining, connection lost), or a stream reset by a proxy whose replica died mid-call (gRPC
// reports INTERNAL "Received RST_STREAM ..."; no server handler sends that message).
bool IsTransient(const grpc::Status& status);

class InbetweenClient {
 public:
  // The least wait before retrying a refusal by the server's --max-heavy-jobs-per-token that
  // follows a transient failure: the token's earlier, broken attempt is usually still winding
  // down on the server until its job notices the cancellation.
  static constexpr std::chrono::milliseconds kOrphanJobBackoff{500};

  explicit InbetweenClient(std::shared_ptr<grpc::Channel> channel, ClientOptions options = {});

  absl::StatusOr<v1::Session> CreateSession(const std::string& display_name,
                                            const v1::Parameters& parameters = {});
  absl::StatusOr<v1::GetSessionResponse> GetSession(const std::string& session_id, bool full);
  // Every session of the caller (all pages).
  absl::StatusOr<std::vector<v1::Session>> ListSessions();
  // Deletes the session at `session.version()` (0 = any version); not retried.
  absl::Status DeleteSession(const v1::Session& session);
  absl::StatusOr<v1::PutDrawingResponse> PutDrawing(const v1::PutDrawingRequest& request);
  absl::StatusOr<v1::Session> SetCorrespondences(const v1::SetCorrespondencesRequest& request);
  absl::StatusOr<v1::BuildMultimeshResult> BuildMultimesh(const v1::Session& session,
                                                          const ProgressCallback& progress);
  // Optimizes at `session.version()` with the session's comesh parameters, or `comesh` when
  // given. A transient failure sends the request again with `resume` (same expected_version);
  // `on_iter` sees each iteration once, in order (a resumed run numbers on from its checkpoint,
  // and iterations received before the failure are not repeated); `progress` sees every
  // Progress message, the server's "resumed after outer N at iteration I" included.
  absl::StatusOr<v1::OptimizeComeshResult> OptimizeComesh(
      const v1::Session& session, const std::function<void(const v1::ComeshIteration&)>& on_iter,
      const ProgressCallback& progress, const v1::ComeshParameters* comesh = nullptr);
  // Streams all frames; `on_frame` (optional) sees each frame as it arrives, once, in order.
  // A transient failure resumes at the next frame; a resumed stream computed from another
  // session version (the session changed meanwhile) is ABORTED.
  absl::StatusOr<FramesResult> Inbetween(
      const std::string& session_id, const v1::InbetweenParameters& parameters,
      const std::function<void(const v1::InbetweenFrame&, uint32_t total)>& on_frame);

  // Cancels the RPC in flight (if any) and every later one, from another thread (Ctrl-C).
  void CancelInFlight();

 private:
  // A context carrying the token and the session id (for proxies' session affinity), registered
  // as the in-flight call for CancelInFlight() until it is destroyed.
  class Call;

  // Runs `rpc` (one attempt in the given context) until it succeeds, fails for good or the
  // attempts run out; for idempotent unary calls only.
  grpc::Status CallWithRetry(const std::string& method, const std::string& session_id,
                             const std::function<grpc::Status(grpc::ClientContext*)>& rpc);
  // Reports the retry and waits the backoff before attempt `failed_attempt + 1`: OK to go on;
  // else what the call returns: `status` itself when it is not transient or the attempts are
  // used up, CANCELLED when CancelInFlight() came during the wait. A refusal by the server's
  // --max-heavy-jobs-per-token on a retry counts as transient (kOrphanJobBackoff).
  grpc::Status PrepareRetry(const std::string& method, int failed_attempt,
                            const grpc::Status& status, uint32_t resume_frame = 0,
                            uint32_t last_iteration = 0);

  std::unique_ptr<v1::Inbetween::Stub> stub_;
  ClientOptions options_;
  std::mutex mu_;
  std::condition_variable cancel_cv_;  // wakes a backoff wait on CancelInFlight()
  grpc::ClientContext* in_flight_ = nullptr;
  bool cancelled_ = false;
};

}  // namespace inbetween::client
