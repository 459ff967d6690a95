// Machine-readable reasons for the errors callers act on (a limit to name, advice to add), so
// that no caller recognises an error by its text. A reason rides an absl::Status as a payload;
// the service sends it with the gRPC status as a google.rpc.ErrorInfo in the status details
// (inbetween.proto, ErrorStatus), and InbetweenClient reads it back into the payload.
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/cord.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"

namespace inbetween::solver {

// The mesher needs more vertices than its limit allows (MultimeshOptions::max_vertices).
inline constexpr absl::string_view kReasonMeshVertexLimit = "MESH_VERTEX_LIMIT";
// An SVG has more points than SvgImportOptions::max_points.
inline constexpr absl::string_view kReasonDrawingPointLimit = "DRAWING_POINT_LIMIT";
// The drawings' boundaries differ in topology (components and holes): cuts or openings needed.
inline constexpr absl::string_view kReasonTopologyDiffers = "TOPOLOGY_DIFFERS";
// The caller's token has as many heavy jobs as the server allows one token.
inline constexpr absl::string_view kReasonHeavyJobsPerToken = "HEAVY_JOBS_PER_TOKEN";
// The session store has no memory left for a new session or a change (Redis at maxmemory).
inline constexpr absl::string_view kReasonStoreFull = "STORE_FULL";
// Every heavy-job slot and queue place is taken.
inline constexpr absl::string_view kReasonServerBusy = "SERVER_BUSY";
// The caller's token holds as many sessions as the server allows one token.
inline constexpr absl::string_view kReasonSessionsPerToken = "SESSIONS_PER_TOKEN";
// The server (or the shared store) holds its maximum number of sessions.
inline constexpr absl::string_view kReasonSessionLimit = "SESSION_LIMIT";

// The payload's type URL, and the ErrorInfo domain the service sends reasons under.
inline constexpr absl::string_view kErrorReasonPayload = "type.inbetween/error-reason";
inline constexpr absl::string_view kErrorDomain = "inbetween.v1";
// The type URL of a google.rpc.ErrorInfo in a google.rpc.Status's details.
inline constexpr absl::string_view kErrorInfoTypeUrl = "type.googleapis.com/google.rpc.ErrorInfo";

// `status` with `reason` attached (an OK status stays OK).
inline absl::Status WithReason(absl::Status status, absl::string_view reason) {
  if (!status.ok()) status.SetPayload(kErrorReasonPayload, absl::Cord(reason));
  return status;
}

// How long a caller should wait before retrying, in ms, as a payload (sent as google.rpc.RetryInfo).
inline constexpr absl::string_view kRetryAfterPayload = "type.inbetween/retry-after-ms";
inline constexpr absl::string_view kRetryInfoTypeUrl = "type.googleapis.com/google.rpc.RetryInfo";
inline constexpr absl::string_view kBadRequestTypeUrl = "type.googleapis.com/google.rpc.BadRequest";

inline absl::Status WithRetryAfter(absl::Status status, int64_t ms) {
  if (!status.ok()) status.SetPayload(kRetryAfterPayload, absl::Cord(absl::StrCat(ms)));
  return status;
}

// The retry delay attached to `status` in ms, or 0.
inline int64_t RetryAfterMs(const absl::Status& status) {
  const auto payload = status.GetPayload(kRetryAfterPayload);
  int64_t ms = 0;
  return payload && absl::SimpleAtoi(std::string(*payload), &ms) ? ms : 0;
}

// The offending request field a client read from a google.rpc.BadRequest, as a payload.
inline constexpr absl::string_view kErrorFieldPayload = "type.inbetween/field";
inline std::string ErrorField(const absl::Status& status) {
  const auto payload = status.GetPayload(kErrorFieldPayload);
  return payload ? std::string(*payload) : std::string();
}

// The reason attached to `status`, or "" when it has none.
inline std::string ErrorReason(const absl::Status& status) {
  const auto payload = status.GetPayload(kErrorReasonPayload);  // absl::optional<absl::Cord>
  return payload ? std::string(*payload) : std::string();
}

// `status` with `prefix` before its message; its code and payloads (the reason) are kept.
inline absl::Status Prefixed(const absl::Status& status, absl::string_view prefix) {
  absl::Status out(status.code(), absl::StrCat(prefix, status.message()));
  status.ForEachPayload(
      [&](absl::string_view url, const absl::Cord& payload) { out.SetPayload(url, payload); });
  return out;
}

}  // namespace inbetween::solver
