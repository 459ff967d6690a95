// Metrics: counters/histograms under one mutex; MetricsHttpServer: a blocking accept loop with a
// poll timeout so that it notices shutdown, one request per connection (Connection: close).
#include "server/metrics.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace inbetween::server {
namespace {

constexpr std::array<double, 12> kBuckets = {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05,
                                             0.1,   0.25,   0.5,   1.0,  5.0,   30.0};

}  // namespace

void Metrics::Observe(Histogram& h, double seconds) {
  if (h.buckets.empty()) h.buckets.assign(kBuckets.size(), 0);
  for (size_t i = 0; i < kBuckets.size(); ++i) {
    if (seconds <= kBuckets[i]) {
      ++h.buckets[i];
      break;
    }
  }
  ++h.count;
  h.sum += seconds;
}

void Metrics::ObserveRpc(absl::string_view method, absl::string_view code, double seconds) {
  std::lock_guard lock(mutex_);
  ++rpc_counts_[{std::string(method), std::string(code)}];
  Observe(rpc_seconds_[absl::StrCat("method=\"", method, "\",code=\"", code, "\"")], seconds);
}

void Metrics::ObserveStage(absl::string_view stage, double seconds) {
  std::lock_guard lock(mutex_);
  Observe(stage_seconds_[absl::StrCat("stage=\"", stage, "\"")], seconds);
}

void Metrics::RenderHistogram(std::string& out, absl::string_view name,
                              const std::map<std::string, Histogram, std::less<>>& histograms) {
  for (const auto& [labels, h] : histograms) {
    uint64_t cumulative = 0;
    for (size_t i = 0; i < kBuckets.size(); ++i) {
      cumulative += h.buckets.empty() ? 0 : h.buckets[i];
      absl::StrAppend(&out, name, "_bucket{", labels, ",le=\"", absl::StrFormat("%g", kBuckets[i]),
                      "\"} ", cumulative, "\n");
    }
    absl::StrAppend(&out, name, "_bucket{", labels, ",le=\"+Inf\"} ", h.count, "\n");
    absl::StrAppend(&out, name, "_sum{", labels, "} ", absl::StrFormat("%.6f", h.sum), "\n");
    absl::StrAppend(&out, name, "_count{", labels, "} ", h.count, "\n");
  }
}

std::string Metrics::Render(const std::vector<Gauge>& gauges) const {
  std::string out;
  std::lock_guard lock(mutex_);
  out += "# HELP inbetween_rpcs_total Finished RPCs by method and status code.\n";
  out += "# TYPE inbetween_rpcs_total counter\n";
  for (const auto& [key, count] : rpc_counts_) {
    absl::StrAppend(&out, "inbetween_rpcs_total{method=\"", key.first, "\",code=\"", key.second,
                    "\"} ", count, "\n");
  }
  out += "# HELP inbetween_rpc_duration_seconds RPC latency by method and status code.\n";
  out += "# TYPE inbetween_rpc_duration_seconds histogram\n";
  RenderHistogram(out, "inbetween_rpc_duration_seconds", rpc_seconds_);
  out += "# HELP inbetween_stage_seconds Solver stage run time by stage.\n";
  out += "# TYPE inbetween_stage_seconds histogram\n";
  RenderHistogram(out, "inbetween_stage_seconds", stage_seconds_);
  absl::StrAppend(&out,
                  "# HELP inbetween_frames_solved_total Inbetween frames solved.\n"
                  "# TYPE inbetween_frames_solved_total counter\n"
                  "inbetween_frames_solved_total ",
                  frames_solved(), "\n");
  for (const Gauge& g : gauges) {
    absl::StrAppend(&out, "# HELP ", g.name, " ", g.help, "\n# TYPE ", g.name, " gauge\n", g.name,
                    " ", absl::StrFormat("%g", g.value), "\n");
  }
  return out;
}

absl::StatusOr<std::unique_ptr<MetricsHttpServer>> MetricsHttpServer::Start(
    const std::string& listen, std::function<std::string()> render) {
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen: '", listen, "' is not HOST:PORT"));
  }
  std::string host = listen.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  const std::string port = listen.substr(colon + 1);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), port.c_str(), &hints, &found) != 0 || found == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen: cannot resolve '", listen, "'"));
  }
  std::unique_ptr<MetricsHttpServer> server(new MetricsHttpServer());
  server->fd_ = socket(found->ai_family, found->ai_socktype | SOCK_CLOEXEC, found->ai_protocol);
  const int one = 1;
  if (server->fd_ >= 0) setsockopt(server->fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  const bool bound = server->fd_ >= 0 &&
                     bind(server->fd_, found->ai_addr, found->ai_addrlen) == 0 &&
                     ::listen(server->fd_, 16) == 0;
  freeaddrinfo(found);
  if (!bound) {
    return absl::UnavailableError(
        absl::StrCat("--metrics-listen: cannot bind '", listen, "': ", std::strerror(errno)));
  }
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  getsockname(server->fd_, reinterpret_cast<sockaddr*>(&address), &length);
  server->port_ =
      ntohs(address.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&address)->sin6_port
                                          : reinterpret_cast<sockaddr_in*>(&address)->sin_port);
  server->render_ = std::move(render);
  server->thread_ = std::thread([s = server.get()] { s->Serve(); });
  return server;
}

MetricsHttpServer::~MetricsHttpServer() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) close(fd_);
}

void MetricsHttpServer::Serve() {
  while (!stop_) {
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    const int client = accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    // Read the request head (up to 8 KiB, 1 s); only the request line matters.
    std::string request;
    char buffer[2048];
    while (request.find("\r\n\r\n") == std::string::npos && request.size() < 8192) {
      pollfd c{client, POLLIN, 0};
      if (poll(&c, 1, 1000) <= 0) break;
      const ssize_t n = read(client, buffer, sizeof(buffer));
      if (n <= 0) break;
      request.append(buffer, static_cast<size_t>(n));
    }
    std::string status = "404 Not Found";
    std::string body = "not found; try GET /metrics\n";
    std::string type = "text/plain; charset=utf-8";
    if (request.rfind("GET /metrics ", 0) == 0 || request.rfind("GET /metrics?", 0) == 0) {
      status = "200 OK";
      body = render_();
      type = "text/plain; version=0.0.4; charset=utf-8";
    }
    const std::string response =
        absl::StrCat("HTTP/1.1 ", status, "\r\nContent-Type: ", type,
                     "\r\nContent-Length: ", body.size(), "\r\nConnection: close\r\n\r\n", body);
    size_t sent = 0;
    while (sent < response.size()) {
      const ssize_t n = send(client, response.data() + sent, response.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) break;
      sent += static_cast<size_t>(n);
    }
    close(client);
  }
}

}  // namespace inbetween::server
