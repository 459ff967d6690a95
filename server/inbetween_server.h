// The Inbetween gRPC server: the service, the session store, health and reflection, an optional
// listening port and an in-process channel (used by the embedded CLI and the tests).
#pragma once

#include <grpcpp/channel.h>
#include <grpcpp/server.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "server/inbetween_service.h"

namespace inbetween::server {

class MetricsHttpServer;

inline constexpr int kMaxMessageBytes = 64 * 1024 * 1024;

struct ServerOptions {
  // "host:port"; empty = no listening port (in-process only); port 0 = pick a free port.
  std::string listen;
  // "memory" (default; the embedded CLI), "dir:PATH" (snapshots, dir_session_store.h) or
  // "redis://HOST:PORT[/DB]" (shared by replicas, redis_session_store.h); anything else ->
  // InvalidArgument naming the flag (--store).
  std::string store = "memory";
  // Sessions of the dir and Redis stores not used for this long are dropped from memory (they
  // stay in the store and reload on next use); 0 = never. --idle-evict-seconds.
  std::chrono::seconds idle_evict{600};
  // Redis store: a session expires this long after its last use (create, write, read); 0 =
  // never. --session-ttl-seconds.
  std::chrono::seconds session_ttl{7 * 24 * 3600};
  // Redis store: a file holding the AUTH password (first line); --redis-password-file.
  std::string redis_password_file;
  bool reflection = true;
  std::chrono::milliseconds shutdown_grace{5000};
  int max_message_bytes = kMaxMessageBytes;  // --max-message-bytes, both directions
  size_t max_sessions = 10000;               // --max-sessions (whole server)
  // Limits, heavy-job pool; tokens and metrics are filled from the fields below.
  ServiceOptions service;
  std::string tokens_file;  // --tokens: bearer tokens required when set
  std::string tls_cert;     // --tls-cert / --tls-key: PEM files; TLS when both are set
  std::string tls_key;
  std::string tls_client_ca;   // --tls-client-ca: require client certificates signed by it
  std::string metrics_listen;  // --metrics-listen HOST:PORT: Prometheus /metrics; empty = off
};

class InbetweenServer {
 public:
  // Errors: INVALID_ARGUMENT naming the flag (--store, --listen), UNAVAILABLE when the address
  // cannot be bound. Note: gRPC's reflection plugin is process-wide; once a server in this
  // process started with reflection, later servers have it too.
  static absl::StatusOr<std::unique_ptr<InbetweenServer>> Start(const ServerOptions& options);
  ~InbetweenServer();  // Shutdown() + Wait()

  std::shared_ptr<grpc::Channel> InProcessChannel();  // same service, no network
  int port() const;                                   // the bound port (0 if not listening)
  int metrics_port() const;                           // 0 without --metrics-listen
  // Stop accepting, let running streams finish up to shutdown_grace, then cancel them (the
  // handlers see the cancellation and stop their solver work). Idempotent, thread-safe.
  void Shutdown();
  void Wait();  // blocks until the server has shut down
  // The Prometheus exposition text served on --metrics-listen.
  std::string RenderMetrics() const;
  // The session store (tests look at its cache).
  SessionStore& store() { return *store_; }

 private:
  InbetweenServer() = default;
  void EvictIdleLoop();
  // The gauges read at each scrape: sessions, heavy-job pool, serving/draining.
  std::vector<Metrics::Gauge> ScrapedGauges() const;

  ServerOptions options_;
  int port_ = 0;
  std::shared_ptr<SessionStore> store_;
  std::shared_ptr<Metrics> metrics_;
  std::unique_ptr<InbetweenService> service_;  // must outlive server_
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<MetricsHttpServer> metrics_server_;
  std::once_flag shutdown_once_;
  std::atomic<bool> draining_{false};
  // Idle eviction (--idle-evict-seconds): a thread sweeping the store's cache.
  std::thread evictor_;
  std::mutex evictor_mutex_;
  std::condition_variable evictor_stop_;
  bool evictor_stopping_ = false;
};

}  // namespace inbetween::server
