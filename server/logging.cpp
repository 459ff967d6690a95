// Logging configuration. The JSON line format uses two custom spdlog flags: %* writes the message
// JSON-escaped, %& the extra fields of an RPC line, so user-provided names cannot break the line.
#include "server/logging.h"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <string_view>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "nlohmann/json.hpp"

namespace inbetween::server {
namespace {

// Whether ConfigureLogging chose JSON lines (LogRpc then passes its fields as JSON fields).
std::atomic<bool> json_lines{false};

// The extra JSON fields (",\"request\":...") of the line being logged on this thread, written by
// the %& flag. spdlog 1.10 has no structured fields (its MDC, from 1.13 on, is the same
// thread-local design); the server's logger is synchronous, so the line is formatted on this
// thread within the spdlog call that set them.
thread_local const std::string* json_fields = nullptr;

// `s` as the inside of a JSON string, escaped by nlohmann::json (bytes that are not UTF-8 become
// U+FFFD: a JSON text is UTF-8).
std::string JsonEscaped(std::string_view s) {
  const std::string quoted =
      nlohmann::json(std::string(s))
          .dump(-1, ' ', /*ensure_ascii=*/false, nlohmann::json::error_handler_t::replace);
  return quoted.substr(1, quoted.size() - 2);
}

class JsonEscapedMessage final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&,
              spdlog::memory_buf_t& dest) override {
    const std::string escaped =
        JsonEscaped(std::string_view(msg.payload.data(), msg.payload.size()));
    dest.append(escaped.data(), escaped.data() + escaped.size());
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<JsonEscapedMessage>();
  }
};

class JsonFields final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg&, const std::tm&,
              spdlog::memory_buf_t& dest) override {
    if (json_fields != nullptr) {
      dest.append(json_fields->data(), json_fields->data() + json_fields->size());
    }
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<JsonFields>();
  }
};

// ,"key":"value" with the value JSON-escaped.
void AppendJsonString(std::string& out, std::string_view key, std::string_view value) {
  out.append(",\"").append(key).append("\":\"");
  out.append(JsonEscaped(value)).append("\"");
}

}  // namespace

absl::Status ConfigureLogging(absl::string_view level, absl::string_view format) {
  spdlog::level::level_enum parsed;
  if (level == "trace") {
    parsed = spdlog::level::trace;
  } else if (level == "debug") {
    parsed = spdlog::level::debug;
  } else if (level == "info") {
    parsed = spdlog::level::info;
  } else if (level == "warn") {
    parsed = spdlog::level::warn;
  } else if (level == "error") {
    parsed = spdlog::level::err;
  } else if (level == "off") {
    parsed = spdlog::level::off;
  } else {
    return absl::InvalidArgumentError(absl::StrCat(
        "--log-level: '", level, "' is not one of trace, debug, info, warn, error, off"));
  }
  if (format != "text" && format != "json") {
    return absl::InvalidArgumentError(
        absl::StrCat("--log-format: '", format, "' is not one of text, json"));
  }
  auto logger = spdlog::get("inbetween-server");
  if (!logger) logger = spdlog::stderr_color_mt("inbetween-server");
  spdlog::set_default_logger(logger);
  spdlog::set_level(parsed);
  if (format == "json") {
    auto formatter = std::make_unique<spdlog::pattern_formatter>(spdlog::pattern_time_type::utc);
    formatter->add_flag<JsonEscapedMessage>('*').add_flag<JsonFields>('&').set_pattern(
        R"({"time":"%Y-%m-%dT%H:%M:%S.%eZ","level":"%l","thread":%t,"msg":"%*"%&})");
    spdlog::set_formatter(std::move(formatter));
  } else {
    spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%^%l%$] %v");
  }
  json_lines = format == "json";
  return absl::OkStatus();
}

void LogRpc(absl::string_view request_id, absl::string_view rpc_name, absl::string_view session_id,
            const grpc::Status& status, double seconds, bool ok_at_info) {
  const std::string_view rpc(rpc_name.data(), rpc_name.size());
  const std::string_view request(request_id.data(), request_id.size());
  const std::string_view session(session_id.data(), session_id.size());
  const std::string code =
      absl::StatusCodeToString(static_cast<absl::StatusCode>(status.error_code()));
  const spdlog::level::level_enum level = !status.ok() ? spdlog::level::warn
                                          : ok_at_info ? spdlog::level::info
                                                       : spdlog::level::debug;
  if (!spdlog::should_log(level)) return;
  if (json_lines) {
    std::string fields;
    AppendJsonString(fields, "request", request);
    AppendJsonString(fields, "method", rpc);
    if (!session.empty()) AppendJsonString(fields, "session", session);
    AppendJsonString(fields, "status", code);
    // Finite in practice (a clock difference); null keeps the line JSON if it ever is not.
    absl::StrAppend(&fields, ",\"seconds\":",
                    std::isfinite(seconds) ? absl::StrFormat("%.6f", seconds) : "null");
    if (!status.ok()) AppendJsonString(fields, "error", status.error_message());
    struct Scope {  // the fields belong to this one line, even if logging throws
      explicit Scope(const std::string* f) { json_fields = f; }
      ~Scope() { json_fields = nullptr; }
    } scope(&fields);
    spdlog::log(level, "{} {} in {:.3f} s", rpc, code, seconds);
    return;
  }
  const std::string session_text =
      session.empty() ? std::string() : absl::StrCat(" session=", session_id);
  if (status.ok()) {
    spdlog::log(level, "request={} rpc={}{} status=OK seconds={:.3f}", request, rpc, session_text,
                seconds);
  } else {
    spdlog::log(level, "request={} rpc={}{} status={} seconds={:.3f} error={}", request, rpc,
                session_text, code, seconds, status.error_message());
  }
}

}  // namespace inbetween::server
