// Thin gRPC client for inbetween.v1.Inbetween (see inbetween_client.h).
#include "client/inbetween_client.h"

#include "absl/strings/str_cat.h"

namespace inbetween::client {

absl::Status FromGrpcStatus(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

InbetweenClient::InbetweenClient(std::shared_ptr<grpc::Channel> channel)
    : stub_(v1::Inbetween::NewStub(std::move(channel))) {}

void InbetweenClient::SetInFlight(grpc::ClientContext* context) {
  std::lock_guard<std::mutex> lock(mu_);
  in_flight_ = context;
  if (context != nullptr && cancelled_) context->TryCancel();
}

void InbetweenClient::CancelInFlight() {
  std::lock_guard<std::mutex> lock(mu_);
  cancelled_ = true;
  if (in_flight_ != nullptr) in_flight_->TryCancel();
}

absl::StatusOr<v1::Session> InbetweenClient::CreateSession(const std::string& display_name) {
  grpc::ClientContext context;
  SetInFlight(&context);
  v1::CreateSessionRequest request;
  request.set_display_name(display_name);
  v1::CreateSessionResponse response;
  grpc::Status status = stub_->CreateSession(&context, request, &response);
  SetInFlight(nullptr);
  if (!status.ok()) return FromGrpcStatus(status);
  return response.session();
}

absl::StatusOr<v1::PutDrawingResponse> InbetweenClient::PutSvgDrawing(
    const v1::Session& session, const std::string& name, const std::string& svg_text) {
  grpc::ClientContext context;
  context.AddMetadata("x-session-id", session.id());
  SetInFlight(&context);
  v1::PutDrawingRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  request.mutable_drawing()->set_name(name);
  request.mutable_drawing()->set_svg(svg_text);
  v1::PutDrawingResponse response;
  grpc::Status status = stub_->PutDrawing(&context, request, &response);
  SetInFlight(nullptr);
  if (!status.ok()) return FromGrpcStatus(status);
  return response;
}

absl::StatusOr<v1::BuildMultimeshResult> InbetweenClient::BuildMultimesh(
    const v1::Session& session, const ProgressCallback& progress) {
  grpc::ClientContext context;
  context.AddMetadata("x-session-id", session.id());
  SetInFlight(&context);
  v1::BuildMultimeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  auto reader = stub_->BuildMultimesh(&context, request);
  v1::BuildMultimeshResponse response;
  v1::BuildMultimeshResult result;
  bool have_result = false;
  while (reader->Read(&response)) {
    if (response.has_progress() && progress) progress(response.progress());
    if (response.has_result()) {
      result = response.result();
      have_result = true;
    }
  }
  grpc::Status status = reader->Finish();
  SetInFlight(nullptr);
  if (!status.ok()) return FromGrpcStatus(status);
  if (!have_result) return absl::InternalError("BuildMultimesh stream ended without a result");
  return result;
}

absl::StatusOr<FramesResult> InbetweenClient::Inbetween(
    const std::string& session_id, const v1::InbetweenParameters& parameters,
    const std::function<void(const v1::InbetweenFrame&, uint32_t total)>& on_frame) {
  grpc::ClientContext context;
  context.AddMetadata("x-session-id", session_id);
  SetInFlight(&context);
  v1::InbetweenRequest request;
  request.set_session_id(session_id);
  *request.mutable_parameters() = parameters;
  auto reader = stub_->Inbetween(&context, request);
  FramesResult result;
  bool have_header = false;
  v1::InbetweenResponse response;
  while (reader->Read(&response)) {
    if (response.has_header()) {
      result.header = response.header();
      have_header = true;
    } else if (response.has_frame()) {
      if (on_frame) on_frame(response.frame(), result.header.frames());
      result.frames.push_back(std::move(*response.mutable_frame()));
    }
  }
  grpc::Status status = reader->Finish();
  SetInFlight(nullptr);
  if (!status.ok()) return FromGrpcStatus(status);
  if (!have_header) return absl::InternalError("Inbetween stream ended without a header");
  if (result.frames.size() != result.header.frames()) {
    return absl::InternalError(absl::StrCat("Inbetween stream sent ", result.frames.size(),
                                            " frames, header announced ",
                                            result.header.frames()));
  }
  return result;
}

}  // namespace inbetween::client
