// inbetween-loadgen's engine (see load_generator.h).
#include "tools/loadgen/load_generator.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <mutex>
#include <set>
#include <thread>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/inbetween_client.h"
#include "nlohmann/json.hpp"

namespace inbetween::loadgen {
namespace {

using Clock = std::chrono::steady_clock;

bool IsUnary(const std::string& rpc) {
  return rpc != "BuildMultimesh" && rpc != "OptimizeComesh" && rpc != "Inbetween";
}

// What every studio shares: the request budget, the deadline and the measurements.
class Run {
 public:
  Run(const LoadGenOptions& options)
      : options_(options), deadline_(Clock::now() + options.duration) {}

  // Claims one request of the budget; false once the budget or the time is used up.
  bool Claim() {
    if (Clock::now() >= deadline_) return false;
    return claimed_.fetch_add(1) < options_.max_requests;
  }

  // Times `call` (one RPC, or one whole stream with its retries) and records its outcome;
  // returns its status. Nothing is sent (kCancelled "budget") when the budget is used up.
  absl::Status Measure(const std::string& rpc, const std::function<absl::Status()>& call) {
    if (!Claim()) return absl::CancelledError("budget");
    const Clock::time_point start = Clock::now();
    absl::Status status = call();
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    std::lock_guard<std::mutex> lock(mu_);
    ++requests_;
    Samples& s = samples_[rpc];
    ++s.calls;
    if (status.ok()) {
      s.ms.push_back(ms);
    } else {
      ++s.errors;
      ++s.errors_by_code[absl::StatusCodeToString(status.code())];
      ++errors_by_code_[absl::StatusCodeToString(status.code())];
    }
    return status;
  }

  // A heavy call (a slot of the server's bounded pool): RESOURCE_EXHAUSTED is the server's
  // documented back-pressure, so the studio waits (100 ms, doubling up to 1.6 s) and asks again,
  // up to 6 times; every attempt is a request in the report.
  absl::Status MeasureHeavy(const std::string& rpc, const std::function<absl::Status()>& call) {
    std::chrono::milliseconds wait(100);
    for (int attempt = 1;; ++attempt) {
      absl::Status status = Measure(rpc, call);
      if (!absl::IsResourceExhausted(status) || attempt == 6) return status;
      std::this_thread::sleep_for(wait);
      wait = std::min(wait * 2, std::chrono::milliseconds(1600));
    }
  }

  // Sessions created and not deleted by the studio that made them.
  void AddSession(const std::string& id) {
    std::lock_guard<std::mutex> lock(mu_);
    ++sessions_created_;
    alive_.insert(id);
  }
  void DeletedSession(const std::string& id) {
    std::lock_guard<std::mutex> lock(mu_);
    alive_.erase(id);
  }
  void LostSession() {
    std::lock_guard<std::mutex> lock(mu_);
    ++lost_;
  }
  void AddFrames(const std::string& digest) {
    std::lock_guard<std::mutex> lock(mu_);
    ++streams_completed_;
    if (first_frames_.empty()) first_frames_ = digest;
    if (digest != first_frames_) frames_identical_ = false;
  }
  void AddRetry() { retries_.fetch_add(1); }
  std::vector<std::string> alive_sessions() {
    std::lock_guard<std::mutex> lock(mu_);
    return {alive_.begin(), alive_.end()};
  }

  LoadReport Report(double seconds) {
    std::lock_guard<std::mutex> lock(mu_);
    LoadReport r;
    r.studios = options_.studios;
    r.seconds = seconds;
    r.requests = requests_;
    r.errors_by_code = errors_by_code_;
    for (const auto& [code, n] : errors_by_code_) r.errors += n;
    std::vector<double> unary;
    for (const auto& [rpc, s] : samples_) {
      RpcSummary& out = r.rpcs[rpc];
      out.calls = s.calls;
      out.errors = s.errors;
      out.errors_by_code = s.errors_by_code;
      out.p50_ms = Percentile(s.ms, 50);
      out.p95_ms = Percentile(s.ms, 95);
      out.p99_ms = Percentile(s.ms, 99);
      out.max_ms = Percentile(s.ms, 100);
      if (IsUnary(rpc)) unary.insert(unary.end(), s.ms.begin(), s.ms.end());
    }
    r.unary_p99_ms = Percentile(unary, 99);
    r.retries = retries_.load();
    r.sessions = sessions_created_;
    r.lost_sessions = lost_;
    r.streams_completed = streams_completed_;
    r.frames_identical = frames_identical_;
    return r;
  }

 private:
  struct Samples {
    int64_t calls = 0, errors = 0;
    std::map<std::string, int64_t> errors_by_code;
    std::vector<double> ms;
  };
  const LoadGenOptions& options_;
  const Clock::time_point deadline_;
  std::atomic<int64_t> claimed_{0};
  std::atomic<int64_t> retries_{0};
  std::mutex mu_;
  int64_t requests_ = 0;
  std::map<std::string, Samples> samples_;
  std::map<std::string, int64_t> errors_by_code_;
  int64_t sessions_created_ = 0;
  int64_t lost_ = 0;
  std::set<std::string> alive_;
  int64_t streams_completed_ = 0;
  std::string first_frames_;
  bool frames_identical_ = true;
};

// The frames' content without the wall-clock seconds, as bytes to compare between streams.
std::string FramesDigest(client::FramesResult frames) {
  std::string bytes = frames.header.SerializeAsString();
  for (v1::InbetweenFrame& f : frames.frames) {
    f.mutable_stats()->clear_seconds();
    bytes += f.SerializeAsString();
  }
  return bytes;
}

// One studio: the animator's loop until the budget or the time runs out; a project ends with
// DeleteSession. A failed call ends the current project (after a short pause; its session is
// kept and checked at the end) and the studio starts a new one.
void Studio(int index, client::InbetweenClient& api, const LoadGenOptions& options, Run& run) {
  // The optimization's bound lives in the session's parameters.
  v1::Parameters parameters;
  parameters.mutable_comesh()->set_max_outer_iterations(options.optimize_outer_iterations);
  parameters.mutable_comesh()->set_max_inner_iterations(20);
  for (int project = 0;; ++project) {
    v1::Session session;
    uint32_t first_drawing = 0;
    absl::Status status = run.Measure("CreateSession", [&] {
      auto created =
          api.CreateSession(absl::StrCat("loadgen studio ", index, " #", project), parameters);
      if (created.ok()) session = *created;
      return created.status();
    });
    if (status.ok()) run.AddSession(session.id());
    for (size_t d = 0; status.ok() && d < options.drawings_svg.size(); ++d) {
      status = run.Measure("PutDrawing", [&] {
        v1::PutDrawingRequest request;
        request.set_session_id(session.id());
        request.set_expected_version(session.version());
        request.mutable_drawing()->set_name(absl::StrCat("key", d + 1, ".svg"));
        request.mutable_drawing()->set_svg(options.drawings_svg[d]);
        auto put = api.PutDrawing(request);
        if (put.ok()) {
          session = put->session();
          if (first_drawing == 0) first_drawing = put->drawing().id();
        }
        return put.status();
      });
    }
    if (status.ok()) {
      status = run.MeasureHeavy("BuildMultimesh", [&] {
        auto built = api.BuildMultimesh(session, nullptr);
        if (built.ok()) session = built->session();
        return built.status();
      });
    }
    if (status.ok() && options.optimize_outer_iterations > 0) {
      status = run.MeasureHeavy("OptimizeComesh", [&] {
        auto optimized = api.OptimizeComesh(session, nullptr, nullptr);
        if (optimized.ok()) session = optimized->session();
        return optimized.status();
      });
    }
    if (status.ok()) {
      status = run.MeasureHeavy("Inbetween", [&] {
        v1::InbetweenParameters parameters;
        parameters.set_frames(options.frames);
        auto frames = api.Inbetween(session.id(), parameters, nullptr);
        if (frames.ok()) run.AddFrames(FramesDigest(*std::move(frames)));
        return frames.status();
      });
    }
    if (status.ok()) {
      status = run.Measure("GetSession", [&] {
        auto got = api.GetSession(session.id(), /*full=*/false);
        if (got.ok()) session = got->session();
        if (absl::IsNotFound(got.status())) run.LostSession();
        return got.status();
      });
    }
    if (status.ok()) {  // an edit: drawing 1 replaced (its multimesh is dropped)
      status = run.Measure("PutDrawing", [&] {
        v1::PutDrawingRequest request;
        request.set_session_id(session.id());
        request.set_expected_version(session.version());
        request.mutable_drawing()->set_id(first_drawing);
        request.mutable_drawing()->set_name("key1-edited.svg");
        request.mutable_drawing()->set_svg(options.drawings_svg[0]);
        auto put = api.PutDrawing(request);
        if (put.ok()) session = put->session();
        return put.status();
      });
    }
    if (status.ok()) {
      status = run.Measure("ListSessions", [&] { return api.ListSessions().status(); });
    }
    if (status.ok()) {
      status = run.Measure("DeleteSession", [&] { return api.DeleteSession(session); });
      if (status.ok()) run.DeletedSession(session.id());
    }
    if (absl::IsCancelled(status) && status.message() == "budget") return;
    if (!status.ok()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

}  // namespace

absl::Status CheckLoopbackTarget(const std::string& target) {
  std::string host, port;
  if (absl::StartsWith(target, "[")) {
    const size_t close = target.find("]:");
    if (close == std::string::npos) return absl::InvalidArgumentError("target: [HOST]:PORT");
    host = target.substr(1, close - 1);
    port = target.substr(close + 2);
  } else {
    const size_t colon = target.rfind(':');
    if (colon == std::string::npos || target.find(':') != colon) {
      return absl::InvalidArgumentError(
          absl::StrCat("target '", target, "': HOST:PORT or [IPV6]:PORT"));
    }
    host = target.substr(0, colon);
    port = target.substr(colon + 1);
  }
  int port_number = 0;
  if (!absl::SimpleAtoi(port, &port_number) || port_number < 1 || port_number > 65535) {
    return absl::InvalidArgumentError(absl::StrCat("target '", target, "': bad port"));
  }
  bool loopback = host == "localhost" || host == "::1";
  int a = 0, b = 0, c = 0, d = 0;
  char tail = 0;
  if (std::sscanf(host.c_str(), "%d.%d.%d.%d%c", &a, &b, &c, &d, &tail) == 4) {
    loopback = a == 127 && b >= 0 && b <= 255 && c >= 0 && c <= 255 && d >= 0 && d <= 255;
  }
  if (!loopback) {
    return absl::InvalidArgumentError(absl::StrCat(
        "target '", target, "' is not a loopback address (127.0.0.0/8, ::1, localhost)"));
  }
  return absl::OkStatus();
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const double rank = std::ceil(p / 100.0 * static_cast<double>(values.size()));
  const size_t index = static_cast<size_t>(std::clamp(rank, 1.0, double(values.size()))) - 1;
  return values[index];
}

absl::StatusOr<LoadReport> RunLoad(std::shared_ptr<grpc::Channel> channel,
                                   const LoadGenOptions& options) {
  if (options.studios < 1) return absl::InvalidArgumentError("studios must be >= 1");
  if (options.drawings_svg.size() < 2) return absl::InvalidArgumentError("need >= 2 drawings");
  if (options.max_requests < 1) return absl::InvalidArgumentError("max_requests must be >= 1");
  Run run(options);
  client::ClientOptions client_options;
  client_options.token = options.token;
  client_options.on_retry = [&run](const client::RetryEvent&) { run.AddRetry(); };
  const Clock::time_point start = Clock::now();
  std::vector<std::thread> studios;
  std::vector<std::unique_ptr<client::InbetweenClient>> clients;
  for (int i = 0; i < options.studios; ++i) {
    clients.push_back(std::make_unique<client::InbetweenClient>(channel, client_options));
  }
  for (int i = 0; i < options.studios; ++i) {
    studios.emplace_back([&, i] { Studio(i, *clients[i], options, run); });
  }
  for (std::thread& t : studios) t.join();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  LoadReport report = run.Report(seconds);
  // Every session created and not deleted must still be there (e.g. after replicas were killed).
  client::InbetweenClient checker(channel, client_options);
  for (const std::string& id : run.alive_sessions()) {
    auto got = checker.GetSession(id, /*full=*/false);
    if (!got.ok() && absl::IsNotFound(got.status())) ++report.lost_sessions;
    if (!got.ok() && !absl::IsNotFound(got.status())) {
      return absl::Status(got.status().code(),
                          absl::StrCat("checking session ", id, ": ", got.status().message()));
    }
  }
  return report;
}

std::string FormatTable(const LoadReport& r) {
  std::string out =
      absl::StrFormat("%-16s %8s %7s %10s %10s %10s %10s  %s\n", "rpc", "calls", "errors", "p50 ms",
                      "p95 ms", "p99 ms", "max ms", "errors by code");
  for (const auto& [rpc, s] : r.rpcs) {
    std::string codes;
    for (const auto& [code, n] : s.errors_by_code) absl::StrAppend(&codes, " ", code, "=", n);
    absl::StrAppendFormat(&out, "%-16s %8d %7d %10.2f %10.2f %10.2f %10.2f %s\n", rpc, s.calls,
                          s.errors, s.p50_ms, s.p95_ms, s.p99_ms, s.max_ms, codes);
  }
  absl::StrAppendFormat(&out,
                        "%d studios, %.1f s, %d requests (%.1f/s), %d errors, unary p99 %.2f ms, "
                        "%d retries, %d sessions (%d lost), %d streams, frames identical: %s\n",
                        r.studios, r.seconds, r.requests,
                        r.seconds > 0 ? r.requests / r.seconds : 0.0, r.errors, r.unary_p99_ms,
                        r.retries, r.sessions, r.lost_sessions, r.streams_completed,
                        r.frames_identical ? "yes" : "NO");
  for (const auto& [code, n] : r.errors_by_code) absl::StrAppendFormat(&out, "  %s: %d\n", code, n);
  return out;
}

std::string FormatJson(const LoadReport& r) {
  nlohmann::json j;
  j["studios"] = r.studios;
  j["seconds"] = r.seconds;
  j["requests"] = r.requests;
  j["requests_per_second"] = r.seconds > 0 ? r.requests / r.seconds : 0.0;
  j["errors"] = r.errors;
  j["errors_by_code"] = nlohmann::json::object();
  for (const auto& [code, n] : r.errors_by_code) j["errors_by_code"][code] = n;
  j["unary_p99_ms"] = r.unary_p99_ms;
  j["retries"] = r.retries;
  j["sessions"] = r.sessions;
  j["lost_sessions"] = r.lost_sessions;
  j["streams_completed"] = r.streams_completed;
  j["frames_identical"] = r.frames_identical;
  for (const auto& [rpc, s] : r.rpcs) {
    j["rpcs"][rpc] = {{"calls", s.calls},   {"errors", s.errors}, {"p50_ms", s.p50_ms},
                      {"p95_ms", s.p95_ms}, {"p99_ms", s.p99_ms}, {"max_ms", s.max_ms}};
    j["rpcs"][rpc]["errors_by_code"] = nlohmann::json::object();
    for (const auto& [code, n] : s.errors_by_code) j["rpcs"][rpc]["errors_by_code"][code] = n;
  }
  return j.dump(2);
}

}  // namespace inbetween::loadgen
