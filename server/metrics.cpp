// Metrics on prometheus-cpp: a Registry with counter and histogram families (prometheus-cpp's
// families and metrics synchronise themselves), TextSerializer for Render, and an Exposer (the
// civetweb HTTP server prometheus-cpp ships) for GET /metrics; at the end, the stack size fix its
// civetweb threads need (pthread_attr_setstacksize).
#include "server/metrics.h"

#include <dlfcn.h>
#include <link.h>
#include <netdb.h>
#include <pthread.h>
#include <sys/socket.h>

#include <cstring>
#include <exception>
#include <sstream>
#include <utility>

#include "absl/strings/str_cat.h"
#include "prometheus/collectable.h"
#include "prometheus/counter.h"
#include "prometheus/exposer.h"
#include "prometheus/family.h"
#include "prometheus/histogram.h"
#include "prometheus/metric_family.h"
#include "prometheus/registry.h"
#include "prometheus/text_serializer.h"

namespace inbetween::server {
namespace {

// Upper bounds in seconds, shared by RPC latency and solver stages: 1 ms to 30 s.
const prometheus::Histogram::BucketBoundaries& Buckets() {
  static const auto* const buckets = new prometheus::Histogram::BucketBoundaries{
      0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 5.0, 30.0};
  return *buckets;
}

}  // namespace

struct Metrics::Families {
  std::shared_ptr<prometheus::Registry> registry = std::make_shared<prometheus::Registry>();
  prometheus::Family<prometheus::Counter>& rpcs =
      prometheus::BuildCounter()
          .Name("inbetween_rpcs_total")
          .Help("Finished RPCs by method and status code.")
          .Register(*registry);
  prometheus::Family<prometheus::Histogram>& rpc_seconds =
      prometheus::BuildHistogram()
          .Name("inbetween_rpc_duration_seconds")
          .Help("RPC latency by method and status code.")
          .Register(*registry);
  prometheus::Family<prometheus::Histogram>& stage_seconds =
      prometheus::BuildHistogram()
          .Name("inbetween_stage_seconds")
          .Help("Solver stage run time by stage.")
          .Register(*registry);
  prometheus::Counter& frames_solved = prometheus::BuildCounter()
                                           .Name("inbetween_frames_solved_total")
                                           .Help("Inbetween frames solved.")
                                           .Register(*registry)
                                           .Add({});
};

Metrics::Metrics() : families_(std::make_unique<Families>()) {}

Metrics::~Metrics() = default;

void Metrics::ObserveRpc(absl::string_view method, absl::string_view code, double seconds) {
  const prometheus::Labels labels = {{"method", std::string(method)}, {"code", std::string(code)}};
  families_->rpcs.Add(labels).Increment();
  families_->rpc_seconds.Add(labels, Buckets()).Observe(seconds);
}

void Metrics::ObserveStage(absl::string_view stage, double seconds) {
  families_->stage_seconds.Add({{"stage", std::string(stage)}}, Buckets()).Observe(seconds);
}

void Metrics::CountFrameSolved() { families_->frames_solved.Increment(); }

uint64_t Metrics::frames_solved() const {
  return static_cast<uint64_t>(families_->frames_solved.Value());
}

std::vector<prometheus::MetricFamily> Metrics::Collect(const std::vector<Gauge>& gauges) const {
  std::vector<prometheus::MetricFamily> families = families_->registry->Collect();
  for (const Gauge& g : gauges) {
    prometheus::MetricFamily family{g.name, g.help, prometheus::MetricType::Gauge, {}};
    family.metric.emplace_back().gauge.value = g.value;
    families.push_back(std::move(family));
  }
  return families;
}

std::string Metrics::Render(const std::vector<Gauge>& gauges) const {
  std::ostringstream out;
  prometheus::TextSerializer().Serialize(out, Collect(gauges));
  return out.str();
}

namespace {

// The gauges are read when scraped, through a Collectable of our own: their values belong to the
// store and the heavy-job pool, and the Exposer has no hook to refresh Gauge objects before it
// collects.
class ScrapedMetrics final : public prometheus::Collectable {
 public:
  explicit ScrapedMetrics(std::function<std::vector<prometheus::MetricFamily>()> collect)
      : collect_(std::move(collect)) {}
  std::vector<prometheus::MetricFamily> Collect() const override { return collect_(); }

 private:
  std::function<std::vector<prometheus::MetricFamily>()> collect_;
};

// `listen` (HOST:PORT, HOST a name or an IPv4 address) as civetweb's listening_ports value, a
// numeric "IPv4:PORT". Debian's civetweb is built without IPv6, so an IPv6 address is refused here
// with a message that says so, rather than failing to bind.
absl::StatusOr<std::string> CivetwebAddress(const std::string& listen) {
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen: '", listen, "' is not HOST:PORT"));
  }
  const std::string host = listen.substr(0, colon);
  const std::string port = listen.substr(colon + 1);
  if (host.find(':') != std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen: '", listen,
                     "' is IPv6, which the metrics endpoint (civetweb, as Debian builds it) does "
                     "not serve; use an IPv4 address such as 0.0.0.0:PORT"));
  }
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), port.c_str(), &hints, &found) != 0 || found == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen: cannot resolve '", listen, "' to an IPv4 address"));
  }
  char numeric_host[NI_MAXHOST];
  char numeric_port[NI_MAXSERV];
  const int named =
      getnameinfo(found->ai_addr, found->ai_addrlen, numeric_host, sizeof(numeric_host),
                  numeric_port, sizeof(numeric_port), NI_NUMERICHOST | NI_NUMERICSERV);
  freeaddrinfo(found);
  if (named != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen: cannot resolve '", listen, "' to an IPv4 address"));
  }
  return absl::StrCat(numeric_host, ":", numeric_port);
}

// Bytes of static TLS (every loaded module's PT_TLS segment, aligned) that glibc places at the top
// of each new thread's stack.
size_t StaticTlsBytes() {
  size_t total = 0;
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* sum) {
        for (int i = 0; i < info->dlpi_phnum; ++i) {
          const ElfW(Phdr)& segment = info->dlpi_phdr[i];
          if (segment.p_type != PT_TLS) continue;
          const size_t align = segment.p_align > 0 ? segment.p_align : 1;
          *static_cast<size_t*>(sum) += (segment.p_memsz + align - 1) / align * align;
        }
        return 0;
      },
      &total);
  return total;
}

}  // namespace

// Declared in this order so that the exposer (whose threads call the collectable) stops first.
struct MetricsHttpServer::Exposed {
  std::shared_ptr<ScrapedMetrics> scraped;
  std::unique_ptr<prometheus::Exposer> exposer;
};

absl::StatusOr<std::unique_ptr<MetricsHttpServer>> MetricsHttpServer::Start(
    const std::string& listen, std::shared_ptr<const Metrics> metrics, GaugeReader gauges) {
  absl::StatusOr<std::string> address = CivetwebAddress(listen);
  if (!address.ok()) return address.status();
  std::unique_ptr<MetricsHttpServer> server(new MetricsHttpServer());
  server->exposed_ = std::make_unique<Exposed>();
  server->exposed_->scraped =
      std::make_shared<ScrapedMetrics>([metrics = std::move(metrics), gauges = std::move(gauges)] {
        return metrics->Collect(gauges());
      });
  // The Exposer throws (civetweb's CivetException) when it cannot listen; exceptions stay in here.
  try {
    server->exposed_->exposer = std::make_unique<prometheus::Exposer>(*address);
  } catch (const std::exception&) {
    return absl::UnavailableError(absl::StrCat("--metrics-listen: cannot bind '", listen,
                                               "' (address in use or not local?)"));
  }
  server->exposed_->exposer->RegisterCollectable(server->exposed_->scraped);
  const std::vector<int> ports = server->exposed_->exposer->GetListeningPorts();
  if (ports.empty()) {
    return absl::UnavailableError(
        absl::StrCat("--metrics-listen: no port bound for '", listen, "'"));
  }
  server->port_ = ports.front();
  return server;
}

MetricsHttpServer::~MetricsHttpServer() = default;

}  // namespace inbetween::server

// Debian's civetweb (under prometheus::Exposer) gives each of its threads a fixed 100 KiB stack,
// and glibc carves the static TLS of every loaded library out of a requested stack size: OpenBLAS
// and METIS hold ~90 KiB of it in our processes, which left civetweb's workers ~7 KiB, and they
// overflowed on the first request. This definition comes before libc's for the dynamic linker; it
// adds the static TLS to the sizes civetweb asks for, so its threads get the usable stack it meant,
// and passes every other caller's request through unchanged.
extern "C" int pthread_attr_setstacksize(pthread_attr_t* attr, size_t size) noexcept {
  using Next = int (*)(pthread_attr_t*, size_t);
  static const auto next = reinterpret_cast<Next>(dlsym(RTLD_NEXT, "pthread_attr_setstacksize"));
  Dl_info caller;
  if (dladdr(__builtin_return_address(0), &caller) != 0 && caller.dli_fname != nullptr &&
      std::strstr(caller.dli_fname, "libcivetweb") != nullptr) {
    static const size_t tls = inbetween::server::StaticTlsBytes();
    size += tls;
  }
  return next(attr, size);
}
