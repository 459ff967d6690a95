// Prometheus metrics (text exposition format 0.0.4) and a tiny HTTP/1.1 responder for
// GET /metrics on --metrics-listen. Counters and histograms are kept here; gauges (active
// sessions, heavy-job queue) are read at scrape time from a callback.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace inbetween::server {

class Metrics {
 public:
  struct Gauge {
    std::string name;  // e.g. "inbetween_active_sessions"
    std::string help;
    double value = 0;
  };

  // One finished RPC: method ("PutDrawing"), status code name ("OK"), seconds.
  void ObserveRpc(absl::string_view method, absl::string_view code, double seconds);
  // Seconds a solver stage ("build", "optimize", "inbetween") ran.
  void ObserveStage(absl::string_view stage, double seconds);
  // One inbetween frame solved (sent or not: frames before a resumed stream's start are solved).
  void CountFrameSolved() { frames_solved_.fetch_add(1, std::memory_order_relaxed); }
  uint64_t frames_solved() const { return frames_solved_.load(std::memory_order_relaxed); }

  // The exposition text: inbetween_rpcs_total{method,code}, inbetween_rpc_duration_seconds
  // histogram {method,code}, inbetween_stage_seconds histogram {stage},
  // inbetween_frames_solved_total, then `gauges`.
  std::string Render(const std::vector<Gauge>& gauges) const;

 private:
  struct Histogram {
    std::vector<uint64_t> buckets;  // cumulative counts are computed at render time
    uint64_t count = 0;
    double sum = 0;
  };
  static void Observe(Histogram& h, double seconds);
  // Keys of `histograms` are the series' label sets, already formatted (method="X",code="Y").
  static void RenderHistogram(std::string& out, absl::string_view name,
                              const std::map<std::string, Histogram, std::less<>>& histograms);

  mutable std::mutex mutex_;
  std::map<std::pair<std::string, std::string>, uint64_t> rpc_counts_;
  std::map<std::string, Histogram, std::less<>> rpc_seconds_;
  std::map<std::string, Histogram, std::less<>> stage_seconds_;
  std::atomic<uint64_t> frames_solved_{0};
};

// Serves GET /metrics (anything else: 404) on HOST:PORT until destroyed.
class MetricsHttpServer {
 public:
  // UNAVAILABLE when the address cannot be bound, INVALID_ARGUMENT when it is not HOST:PORT.
  static absl::StatusOr<std::unique_ptr<MetricsHttpServer>> Start(
      const std::string& listen, std::function<std::string()> render);
  ~MetricsHttpServer();
  int port() const { return port_; }

 private:
  MetricsHttpServer() = default;
  void Serve();

  int fd_ = -1;
  int port_ = 0;
  std::atomic<bool> stop_{false};
  std::function<std::string()> render_;
  std::thread thread_;
};

}  // namespace inbetween::server
