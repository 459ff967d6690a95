// Logging configuration. The JSON line format uses a custom spdlog flag (%*) that writes the
// message JSON-escaped, so user-provided names in messages cannot break the line.
#include "server/logging.h"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"

namespace inbetween::server {
namespace {

class JsonEscapedMessage final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&,
              spdlog::memory_buf_t& dest) override {
    for (char c : msg.payload) {
      switch (c) {
        case '"':
          Append(dest, "\\\"");
          break;
        case '\\':
          Append(dest, "\\\\");
          break;
        case '\n':
          Append(dest, "\\n");
          break;
        case '\r':
          Append(dest, "\\r");
          break;
        case '\t':
          Append(dest, "\\t");
          break;
        default:
          if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(c));
            Append(dest, buf);
          } else {
            dest.push_back(c);
          }
      }
    }
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<JsonEscapedMessage>();
  }

 private:
  static void Append(spdlog::memory_buf_t& dest, std::string_view s) {
    dest.append(s.data(), s.data() + s.size());
  }
};

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
    formatter->add_flag<JsonEscapedMessage>('*').set_pattern(
        R"({"time":"%Y-%m-%dT%H:%M:%S.%eZ","level":"%l","thread":%t,"msg":"%*"})");
    spdlog::set_formatter(std::move(formatter));
  } else {
    spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%^%l%$] %v");
  }
  return absl::OkStatus();
}

void LogRpc(absl::string_view request_id, absl::string_view rpc_name, absl::string_view session_id,
            const grpc::Status& status, double seconds, bool ok_at_info) {
  const std::string_view rpc(rpc_name.data(), rpc_name.size());
  const std::string_view request(request_id.data(), request_id.size());
  const std::string session =
      session_id.empty() ? std::string() : absl::StrCat(" session=", session_id);
  if (status.ok()) {
    spdlog::log(ok_at_info ? spdlog::level::info : spdlog::level::debug,
                "request={} rpc={}{} status=OK seconds={:.3f}", request, rpc, session, seconds);
  } else {
    spdlog::warn("request={} rpc={}{} status={} seconds={:.3f} error={}", request, rpc, session,
                 absl::StatusCodeToString(static_cast<absl::StatusCode>(status.error_code())),
                 seconds, status.error_message());
  }
}

}  // namespace inbetween::server
