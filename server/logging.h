// spdlog set-up for the server (level and text/JSON line format) and the per-RPC log line.
#pragma once

#include <grpcpp/support/status.h>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace inbetween::server {

// level: trace|debug|info|warn|error|off. format: text|json. Logs go to stderr. In JSON mode
// each line is one object {"time","level","thread","msg"} (RPC lines have more fields, LogRpc);
// strings are JSON-escaped (quote, backslash and control characters; bytes that are not UTF-8
// become U+FFFD), nothing else is transformed. Bad values are INVALID_ARGUMENT naming the flag
// (--log-level / --log-format).
absl::Status ConfigureLogging(absl::string_view level, absl::string_view format);

// One line per finished RPC: request id, method, session (when known), status, duration; at
// info (or debug when !ok_at_info, e.g. the embedded CLI) when OK, warn otherwise with the
// error message. Text: "request=ID rpc=METHOD[ session=ID] status=CODE seconds=S.SSS[ error=...]".
// JSON: those as fields beside time/level/thread and a short msg ("METHOD CODE in S.SSS s"):
// "request", "method", "session" (only when known), "status" (the code's name), "seconds" (a
// number) and "error" (only when not OK).
void LogRpc(absl::string_view request_id, absl::string_view rpc, absl::string_view session_id,
            const grpc::Status& status, double seconds, bool ok_at_info = true);

}  // namespace inbetween::server
