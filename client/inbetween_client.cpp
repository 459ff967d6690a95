// Thin gRPC client for inbetween.v1.Inbetween (see inbetween_client.h).
#include "client/inbetween_client.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "solver/core/error_reason.h"

namespace inbetween::client {

namespace {

// gRPC's text for a message over a size limit (message_size filter): "Received message larger
// than max (A vs. B)" / "Sent message larger than max (A vs. B)". Empty when `message` is not it.
std::string NameMessageSizeLimit(const std::string& message) {
  long long size = 0, limit = 0;
  char direction[16] = {};
  if (std::sscanf(message.c_str(), "%15s message larger than max (%lld vs. %lld)", direction, &size,
                  &limit) != 3) {
    return "";
  }
  const std::string which = direction;
  if (which != "Received" && which != "Sent") return "";
  const bool request = which == "Received";  // received by the server
  return absl::StrCat(
      request ? "the request is " : "the reply is ", size, " bytes, over the server's limit of ",
      limit, " bytes (inbetween-server --max-message-bytes ", limit, "): ",
      request ? "send smaller drawings (fewer points) or raise the server's --max-message-bytes"
              : "raise the server's --max-message-bytes or ask for less (a smaller mesh, fewer "
                "vertices per frame)",
      " [gRPC: ", message, "]");
}

}  // namespace

absl::Status FromGrpcStatus(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  if (status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED) {
    if (std::string named = NameMessageSizeLimit(status.error_message()); !named.empty()) {
      return absl::ResourceExhaustedError(named);
    }
  }
  absl::Status out(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
  // The service's reason, sent as a google.rpc.ErrorInfo in the status details.
  v1::ErrorStatus details;
  if (status.error_details().empty() || !details.ParseFromString(status.error_details())) {
    return out;
  }
  for (const v1::ErrorDetail& detail : details.details()) {
    v1::ErrorInfo info;
    v1::BadRequest bad;
    v1::RetryInfo retry;
    if (detail.type_url() == solver::kErrorInfoTypeUrl && info.ParseFromString(detail.value()) &&
        info.domain() == solver::kErrorDomain && !info.reason().empty()) {
      out = solver::WithReason(out, info.reason());
    } else if (detail.type_url() == solver::kBadRequestTypeUrl &&
               bad.ParseFromString(detail.value()) && bad.field_violations_size() > 0) {
      out.SetPayload(solver::kErrorFieldPayload, absl::Cord(bad.field_violations(0).field()));
    } else if (detail.type_url() == solver::kRetryInfoTypeUrl &&
               retry.ParseFromString(detail.value())) {
      out = solver::WithRetryAfter(out, retry.retry_delay().seconds() * 1000 +
                                            retry.retry_delay().nanos() / 1'000'000);
    }
  }
  return out;
}

std::shared_ptr<grpc::Channel> CreateChannelForServer(
    const std::string& target, const std::shared_ptr<grpc::ChannelCredentials>& credentials) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);
  return grpc::CreateCustomChannel(target, credentials, args);
}

bool IsTransient(const grpc::Status& status) {
  if (status.error_code() == grpc::StatusCode::UNAVAILABLE) return true;
  // nginx answers a replica that vanished mid-stream with RST_STREAM(INTERNAL_ERROR), which
  // gRPC turns into this status; a server's own INTERNAL never has this message.
  return status.error_code() == grpc::StatusCode::INTERNAL &&
         absl::StartsWith(status.error_message(), "Received RST_STREAM");
}

// The server's per-token heavy-job limit (server/heavy_jobs.cpp). After a transient failure it is
// most likely our own broken attempt, whose job the server is still winding down: worth a retry.
bool IsOwnHeavyJobLimit(const grpc::Status& status) {
  return solver::ErrorReason(FromGrpcStatus(status)) == solver::kReasonHeavyJobsPerToken;
}

// gRPC aborts the process on a metadata value outside printable ASCII (API misuse), so such a
// value (a session id or token typed with a control character) is not sent as metadata: the
// server then judges the id in the request itself (NOT_FOUND) or sees no token (UNAUTHENTICATED).
bool IsLegalMetadataValue(const std::string& value) {
  return std::all_of(value.begin(), value.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
}

class InbetweenClient::Call {
 public:
  Call(InbetweenClient* client, const std::string& session_id) : client_(client) {
    const std::string& token = client->options_.token;
    if (!token.empty() && IsLegalMetadataValue(token)) {
      context.AddMetadata("authorization", absl::StrCat("Bearer ", token));
    }
    if (!session_id.empty() && IsLegalMetadataValue(session_id)) {
      context.AddMetadata("x-session-id", session_id);
    }
    std::lock_guard<std::mutex> lock(client_->mu_);
    client_->in_flight_ = &context;
    if (client_->cancelled_) context.TryCancel();
  }
  ~Call() {
    std::lock_guard<std::mutex> lock(client_->mu_);
    client_->in_flight_ = nullptr;
  }
  grpc::ClientContext context;

 private:
  InbetweenClient* client_;
};

InbetweenClient::InbetweenClient(std::shared_ptr<grpc::Channel> channel, ClientOptions options)
    : stub_(v1::Inbetween::NewStub(std::move(channel))), options_(std::move(options)) {}

void InbetweenClient::CancelInFlight() {
  std::lock_guard<std::mutex> lock(mu_);
  cancelled_ = true;
  if (in_flight_ != nullptr) in_flight_->TryCancel();
  cancel_cv_.notify_all();
}

grpc::Status InbetweenClient::PrepareRetry(const std::string& method, int failed_attempt,
                                           const grpc::Status& status, uint32_t resume_frame,
                                           uint32_t last_iteration) {
  const RetryOptions& retry = options_.retry;
  const bool orphan = failed_attempt > 1 && IsOwnHeavyJobLimit(status);
  if ((!IsTransient(status) && !orphan) || failed_attempt >= retry.max_attempts) return status;
  double ms =
      std::min(static_cast<double>(retry.max_backoff.count()),
               retry.initial_backoff.count() * std::pow(retry.multiplier, failed_attempt - 1));
  // The earlier attempt's job needs the server to notice the cancellation (its next check).
  if (orphan) ms = std::max(ms, static_cast<double>(kOrphanJobBackoff.count()));
  const std::chrono::milliseconds backoff(static_cast<int64_t>(ms));
  if (options_.on_retry) {
    options_.on_retry(RetryEvent{.method = method,
                                 .failed_attempt = failed_attempt,
                                 .status = FromGrpcStatus(status),
                                 .backoff = backoff,
                                 .resume_frame = resume_frame,
                                 .last_iteration = last_iteration});
  }
  std::unique_lock<std::mutex> lock(mu_);
  if (cancel_cv_.wait_for(lock, backoff, [this] { return cancelled_; })) {
    return grpc::Status(grpc::StatusCode::CANCELLED,
                        absl::StrCat(method, " cancelled while waiting to retry"));
  }
  return grpc::Status::OK;
}

grpc::Status InbetweenClient::CallWithRetry(
    const std::string& method, const std::string& session_id,
    const std::function<grpc::Status(grpc::ClientContext*)>& rpc) {
  for (int attempt = 1;; ++attempt) {
    grpc::Status status;
    {
      Call call(this, session_id);
      status = rpc(&call.context);
    }
    if (status.ok()) return status;
    if (grpc::Status retry = PrepareRetry(method, attempt, status); !retry.ok()) return retry;
  }
}

absl::StatusOr<v1::Session> InbetweenClient::CreateSession(const std::string& display_name,
                                                           const v1::Parameters& parameters) {
  Call call(this, "");
  v1::CreateSessionRequest request;
  request.set_display_name(display_name);
  *request.mutable_parameters() = parameters;
  v1::CreateSessionResponse response;
  grpc::Status status = stub_->CreateSession(&call.context, request, &response);
  if (!status.ok()) return FromGrpcStatus(status);
  return response.session();
}

absl::StatusOr<v1::GetSessionResponse> InbetweenClient::GetSession(const std::string& session_id,
                                                                   bool full) {
  v1::GetSessionRequest request;
  request.set_session_id(session_id);
  request.set_full(full);
  v1::GetSessionResponse response;
  grpc::Status status = CallWithRetry("GetSession", session_id, [&](grpc::ClientContext* context) {
    response.Clear();
    return stub_->GetSession(context, request, &response);
  });
  if (!status.ok()) return FromGrpcStatus(status);
  return response;
}

absl::StatusOr<std::vector<v1::Session>> InbetweenClient::ListSessions() {
  std::vector<v1::Session> sessions;
  v1::ListSessionsRequest request;
  request.set_page_size(1000);
  do {
    v1::ListSessionsResponse response;
    grpc::Status status = CallWithRetry("ListSessions", "", [&](grpc::ClientContext* context) {
      response.Clear();
      return stub_->ListSessions(context, request, &response);
    });
    if (!status.ok()) return FromGrpcStatus(status);
    for (auto& s : *response.mutable_sessions()) sessions.push_back(std::move(s));
    request.set_page_token(response.next_page_token());
  } while (!request.page_token().empty());
  return sessions;
}

absl::Status InbetweenClient::DeleteSession(const v1::Session& session) {
  Call call(this, session.id());
  v1::DeleteSessionRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  v1::DeleteSessionResponse response;
  return FromGrpcStatus(stub_->DeleteSession(&call.context, request, &response));
}

absl::StatusOr<v1::PutDrawingResponse> InbetweenClient::PutDrawing(
    const v1::PutDrawingRequest& request) {
  Call call(this, request.session_id());
  v1::PutDrawingResponse response;
  grpc::Status status = stub_->PutDrawing(&call.context, request, &response);
  if (!status.ok()) return FromGrpcStatus(status);
  return response;
}

absl::StatusOr<v1::Session> InbetweenClient::SetCorrespondences(
    const v1::SetCorrespondencesRequest& request) {
  Call call(this, request.session_id());
  v1::SetCorrespondencesResponse response;
  grpc::Status status = stub_->SetCorrespondences(&call.context, request, &response);
  if (!status.ok()) return FromGrpcStatus(status);
  return response.session();
}

absl::StatusOr<v1::BuildMultimeshResult> InbetweenClient::BuildMultimesh(
    const v1::Session& session, const ProgressCallback& progress) {
  v1::BuildMultimeshRequest request;
  request.set_session_id(session.id());
  // Every attempt names the same version: a build that died before storing its multimesh left
  // the session unchanged, so the same request builds it again (deterministically, the same
  // multimesh); one that stored it before dying makes the retry ABORTED, and the caller re-reads.
  request.set_expected_version(session.version());
  for (int attempt = 1;; ++attempt) {
    Call call(this, session.id());
    auto reader = stub_->BuildMultimesh(&call.context, request);
    v1::BuildMultimeshResponse response;
    std::optional<v1::BuildMultimeshResult> result;
    while (reader->Read(&response)) {
      if (response.has_progress() && progress) progress(response.progress());
      if (response.has_result()) result = std::move(*response.mutable_result());
    }
    grpc::Status status = reader->Finish();
    // The result is the last message, sent after the session was written.
    if (result) return *std::move(result);
    if (status.ok()) return absl::InternalError("BuildMultimesh stream ended without a result");
    grpc::Status retry = PrepareRetry("BuildMultimesh", attempt, status, 0, 0);
    if (!retry.ok()) return FromGrpcStatus(retry);
  }
}

absl::StatusOr<v1::OptimizeComeshResult> InbetweenClient::OptimizeComesh(
    const v1::Session& session, const std::function<void(const v1::ComeshIteration&)>& on_iter,
    const ProgressCallback& progress, const v1::ComeshParameters* comesh) {
  v1::OptimizeComeshRequest request;
  request.set_session_id(session.id());
  // Every attempt names the version the first one started from: the server accepts it while
  // the session changed only by this optimization's own checkpoints.
  request.set_expected_version(session.version());
  if (comesh != nullptr) *request.mutable_comesh() = *comesh;
  uint32_t last_iteration = 0;  // iterations up to this one reached on_iter already
  for (int attempt = 1;; ++attempt) {
    request.set_resume(attempt > 1);
    Call call(this, session.id());
    auto reader = stub_->OptimizeComesh(&call.context, request);
    v1::OptimizeComeshResponse response;
    std::optional<v1::OptimizeComeshResult> result;
    while (reader->Read(&response)) {
      if (response.has_iteration() && response.iteration().inner() > last_iteration) {
        last_iteration = response.iteration().inner();
        if (on_iter) on_iter(response.iteration());
      }
      if (response.has_progress() && progress) progress(response.progress());
      if (response.has_result()) result = std::move(*response.mutable_result());
    }
    grpc::Status status = reader->Finish();
    // The result is the last message, sent after the session was written: done even if the
    // connection broke after it.
    if (result) return *std::move(result);
    if (status.ok()) return absl::InternalError("OptimizeComesh stream ended without a result");
    grpc::Status retry = PrepareRetry("OptimizeComesh", attempt, status, 0, last_iteration);
    if (!retry.ok()) return FromGrpcStatus(retry);
  }
}

absl::StatusOr<FramesResult> InbetweenClient::Inbetween(
    const std::string& session_id, const v1::InbetweenParameters& parameters,
    const std::function<void(const v1::InbetweenFrame&, uint32_t total)>& on_frame) {
  v1::InbetweenRequest request;
  request.set_session_id(session_id);
  *request.mutable_parameters() = parameters;
  FramesResult result;
  bool have_header = false;
  // InbetweenResponse.art messages appended to result.header.art (of header.art_messages).
  uint32_t art_received = 0;
  for (int attempt = 1;; ++attempt) {
    // Resume: the next attempt starts at the first frame not received yet.
    const uint32_t next = static_cast<uint32_t>(result.frames.size());
    request.set_start_frame(next);
    Call call(this, session_id);
    auto reader = stub_->Inbetween(&call.context, request);
    absl::Status mismatch;
    v1::InbetweenResponse response;
    while (mismatch.ok() && reader->Read(&response)) {
      if (response.has_header()) {
        if (!have_header) {
          result.header = response.header();
          have_header = true;
        } else if (response.header().session_version() != result.header.session_version() ||
                   response.header().frames() != result.header.frames() ||
                   response.header().triangles_size() != result.header.triangles_size()) {
          // Another version would give other frames: a mix of two runs is never returned.
          mismatch = absl::AbortedError(absl::StrCat(
              "session ", session_id, " changed from version ", result.header.session_version(),
              " to ", response.header().session_version(), " while its frames were streamed (",
              result.frames.size(), " of ", result.header.frames(), " received); start again"));
        } else if (art_received < result.header.art_messages()) {
          // The art was cut off with the connection: collect it again from this header.
          *result.header.mutable_art() = response.header().art();
          art_received = 0;
        }
      } else if (response.has_art()) {
        if (art_received == result.header.art_messages()) continue;  // a resumed stream's copy
        v1::KeyArt* key = nullptr;
        for (v1::KeyArt& k : *result.header.mutable_art()) {
          if (k.key() == response.art().key()) key = &k;
        }
        if (key == nullptr) {
          mismatch = absl::InternalError(absl::StrCat(
              "Inbetween stream sent art for key ", response.art().key(), ", not in its header"));
          break;
        }
        for (v1::EmbeddedArtLayer& layer : *response.mutable_art()->mutable_layers()) {
          *key->add_layers() = std::move(layer);
        }
        ++art_received;
      } else if (response.has_frame()) {
        if (response.frame().index() != result.frames.size()) {
          mismatch = absl::InternalError(absl::StrCat("Inbetween stream sent frame ",
                                                      response.frame().index(), ", expected ",
                                                      result.frames.size()));
          break;
        }
        if (on_frame) on_frame(response.frame(), result.header.frames());
        result.frames.push_back(std::move(*response.mutable_frame()));
      }
    }
    if (!mismatch.ok()) {
      call.context.TryCancel();
      reader->Finish();
      return mismatch;
    }
    grpc::Status status = reader->Finish();
    if (status.ok()) break;
    // Every frame arrived before the connection broke: nothing to resume.
    if (have_header && result.frames.size() == result.header.frames()) break;
    grpc::Status retry =
        PrepareRetry("Inbetween", attempt, status, static_cast<uint32_t>(result.frames.size()));
    if (!retry.ok()) return FromGrpcStatus(retry);
  }
  if (!have_header) return absl::InternalError("Inbetween stream ended without a header");
  if (art_received != result.header.art_messages()) {
    return absl::InternalError(absl::StrCat("Inbetween stream sent ", art_received,
                                            " art messages, header announced ",
                                            result.header.art_messages()));
  }
  if (result.frames.size() != result.header.frames()) {
    return absl::InternalError(absl::StrCat("Inbetween stream sent ", result.frames.size(),
                                            " frames, header announced ", result.header.frames()));
  }
  return result;
}

}  // namespace inbetween::client
