// Prometheus metrics through prometheus-cpp. Metrics owns a prometheus::Registry with the RPC
// counters and latency histograms, the solver stage histograms and the frames-solved counter;
// gauges whose values live elsewhere (sessions, heavy-job pool) are read at scrape time from a
// callback. MetricsHttpServer serves both on GET /metrics with prometheus::Exposer (civetweb).
// prometheus-cpp stays out of this header (it is installed with the library): consumers that
// include it need no prometheus-cpp headers.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace prometheus {
struct MetricFamily;
}  // namespace prometheus

namespace inbetween::server {

class Metrics {
 public:
  struct Gauge {
    std::string name;  // e.g. "inbetween_active_sessions"
    std::string help;
    double value = 0;
  };

  Metrics();
  ~Metrics();
  Metrics(const Metrics&) = delete;
  Metrics& operator=(const Metrics&) = delete;

  // One finished RPC: method ("PutDrawing"), status code name ("OK"), seconds.
  void ObserveRpc(absl::string_view method, absl::string_view code, double seconds);
  // Seconds a solver stage ("build", "optimize", "inbetween") ran.
  void ObserveStage(absl::string_view stage, double seconds);
  // One inbetween frame solved (sent or not: frames before a resumed stream's start are solved).
  void CountFrameSolved();
  uint64_t frames_solved() const;

  // The text exposition format (0.0.4, prometheus-cpp's TextSerializer): inbetween_rpcs_total
  // {code,method}, inbetween_rpc_duration_seconds histogram {code,method},
  // inbetween_stage_seconds histogram {stage}, inbetween_frames_solved_total, then `gauges`.
  // A family without any observation yet is left out.
  std::string Render(const std::vector<Gauge>& gauges) const;

 private:
  friend class MetricsHttpServer;
  // The registry's families followed by one gauge family per entry of `gauges`.
  std::vector<prometheus::MetricFamily> Collect(const std::vector<Gauge>& gauges) const;

  struct Families;  // the prometheus-cpp registry and its families
  std::unique_ptr<Families> families_;
};

// Serves GET /metrics on HOST:PORT with prometheus::Exposer until destroyed: the families of
// `metrics` and the gauges `gauges()` returns, called on every scrape. Other paths: 404.
class MetricsHttpServer {
 public:
  using GaugeReader = std::function<std::vector<Metrics::Gauge>()>;
  // INVALID_ARGUMENT when `listen` is not HOST:PORT with an IPv4 host (a name or an address;
  // Debian's civetweb has no IPv6), UNAVAILABLE when it cannot be bound; both name
  // --metrics-listen. Port 0 picks a free port (port()).
  static absl::StatusOr<std::unique_ptr<MetricsHttpServer>> Start(
      const std::string& listen, std::shared_ptr<const Metrics> metrics, GaugeReader gauges);
  ~MetricsHttpServer();
  int port() const { return port_; }

 private:
  MetricsHttpServer() = default;

  struct Exposed;  // the exposer and the collectable it scrapes
  std::unique_ptr<Exposed> exposed_;
  int port_ = 0;
};

}  // namespace inbetween::server
